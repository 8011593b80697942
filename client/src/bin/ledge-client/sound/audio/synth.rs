//! A small deterministic sfxr-style synthesizer: the game's sound effects
//! are computed at start, so the client ships no audio files.
//!
//! An effect is one or more [`Tone`]s mixed together. A tone is what one
//! sfxr sound is: an oscillator ([`Wave`]) whose frequency slides
//! exponentially from [`Tone::freq`] to [`Tone::freq_end`], with optional
//! vibrato, shaped by an attack / sustain / decay envelope and an optional
//! one-pole low-pass. Rendering runs at [`OVERSAMPLE`] times the output rate
//! and averages down (less aliasing from the naive square and saw), removes
//! DC with a high-pass, and normalises the peak to the preset's loudness.
//!
//! Everything here is pure: the same [`Tone`]s give the same samples
//! (noise comes from a seeded xorshift generator, not from the OS).

use std::f64::consts::TAU;

use super::effect::Effect;

/// Output sample rate, Hz (mono).
pub const SAMPLE_RATE: u32 = 44_100;

/// Internal oversampling factor.
pub const OVERSAMPLE: u32 = 4;

/// The oscillator of a [`Tone`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Wave {
    /// A pulse wave; `duty` is the high part of a period (0.5: square).
    Square {
        /// Fraction of the period spent high, clamped to 0.05..=0.95.
        duty: f32,
    },
    /// A rising sawtooth.
    Saw,
    /// A triangle.
    Triangle,
    /// A sine.
    Sine,
    /// sfxr's noise: a new random level every half period, so the
    /// frequency sets how bright the noise is.
    Noise,
}

/// One synthesized voice of an effect (the parameters of one sfxr sound).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Tone {
    /// When the tone starts, seconds after the effect's start.
    pub start: f32,
    /// The oscillator.
    pub wave: Wave,
    /// Frequency at the start, Hz.
    pub freq: f32,
    /// Frequency at the end of the decay, Hz (the slide is exponential;
    /// equal to `freq` for none).
    pub freq_end: f32,
    /// Vibrato depth in semitones (0 for none).
    pub vibrato_depth: f32,
    /// Vibrato rate, Hz.
    pub vibrato_rate: f32,
    /// Attack (linear rise), seconds.
    pub attack: f32,
    /// Sustain at full level, seconds.
    pub sustain: f32,
    /// Decay to silence (quadratic), seconds.
    pub decay: f32,
    /// One-pole low-pass cut-off, Hz (0 for none).
    pub lowpass: f32,
    /// Relative level of this tone within its effect.
    pub gain: f32,
    /// Seed of the noise generator (only [`Wave::Noise`] uses it).
    pub seed: u32,
}

impl Tone {
    /// A plain tone: `wave` at `freq` Hz, 2 ms attack, `sustain` then
    /// `decay` seconds, full gain, no slide, no vibrato, no filter.
    pub const fn new(wave: Wave, freq: f32, sustain: f32, decay: f32) -> Tone {
        Tone {
            start: 0.0,
            wave,
            freq,
            freq_end: freq,
            vibrato_depth: 0.0,
            vibrato_rate: 0.0,
            attack: 0.002,
            sustain,
            decay,
            lowpass: 0.0,
            gain: 1.0,
            seed: 0x9E37_79B9,
        }
    }

    /// Starts `seconds` after the effect's start.
    pub const fn at(mut self, seconds: f32) -> Tone {
        self.start = seconds;
        self
    }

    /// Slides (exponentially) to `freq_end` Hz over the tone.
    pub const fn slide_to(mut self, freq_end: f32) -> Tone {
        self.freq_end = freq_end;
        self
    }

    /// Vibrato of `depth` semitones at `rate` Hz.
    pub const fn vibrato(mut self, depth: f32, rate: f32) -> Tone {
        self.vibrato_depth = depth;
        self.vibrato_rate = rate;
        self
    }

    /// Attack time, seconds.
    pub const fn attack(mut self, seconds: f32) -> Tone {
        self.attack = seconds;
        self
    }

    /// One-pole low-pass at `cutoff` Hz.
    pub const fn lowpass(mut self, cutoff: f32) -> Tone {
        self.lowpass = cutoff;
        self
    }

    /// Relative level within the effect.
    pub const fn gain(mut self, gain: f32) -> Tone {
        self.gain = gain;
        self
    }

    /// Seed of the noise generator.
    pub const fn seed(mut self, seed: u32) -> Tone {
        self.seed = seed;
        self
    }

    /// Length of the tone (attack + sustain + decay), seconds.
    pub fn duration(&self) -> f32 {
        self.attack.max(0.0) + self.sustain.max(0.0) + self.decay.max(0.0)
    }

    /// Envelope level at `t` seconds into the tone (0..=1).
    fn envelope(&self, t: f64) -> f64 {
        let attack = f64::from(self.attack.max(0.0));
        let sustain = f64::from(self.sustain.max(0.0));
        let decay = f64::from(self.decay.max(0.0));
        if t < 0.0 {
            0.0
        } else if t < attack {
            t / attack
        } else if t < attack + sustain {
            1.0
        } else if t < attack + sustain + decay {
            let x = 1.0 - (t - attack - sustain) / decay;
            x * x
        } else {
            0.0
        }
    }

    /// Instantaneous frequency at `t` seconds into the tone, Hz.
    fn frequency(&self, t: f64) -> f64 {
        let f0 = f64::from(self.freq.max(1.0));
        let f1 = f64::from(self.freq_end.max(1.0));
        let duration = f64::from(self.duration()).max(1e-6);
        let x = (t / duration).clamp(0.0, 1.0);
        let mut f = f0 * (f1 / f0).powf(x);
        if self.vibrato_depth != 0.0 {
            let semis =
                f64::from(self.vibrato_depth) * (TAU * f64::from(self.vibrato_rate) * t).sin();
            f *= (semis / 12.0).exp2();
        }
        f
    }
}

/// A small xorshift generator: deterministic noise.
#[derive(Debug, Clone)]
struct XorShift(u32);

impl XorShift {
    fn new(seed: u32) -> XorShift {
        XorShift(if seed == 0 { 0x1234_5678 } else { seed })
    }

    /// Uniform in -1..1.
    fn next(&mut self) -> f64 {
        let mut x = self.0;
        x ^= x << 13;
        x ^= x >> 17;
        x ^= x << 5;
        self.0 = x;
        f64::from(x) / f64::from(u32::MAX) * 2.0 - 1.0
    }
}

/// Renders one tone at the oversampled rate, added into `buf` from the
/// tone's start.
fn render_tone(tone: &Tone, buf: &mut [f64]) {
    let rate = f64::from(SAMPLE_RATE * OVERSAMPLE);
    let first = (f64::from(tone.start.max(0.0)) * rate).round() as usize;
    let len = (f64::from(tone.duration()) * rate).ceil() as usize;
    let mut phase = 0.0f64;
    let mut rng = XorShift::new(tone.seed);
    let mut noise = rng.next();
    let alpha = if tone.lowpass > 0.0 {
        1.0 - (-TAU * f64::from(tone.lowpass) / rate).exp()
    } else {
        1.0
    };
    let mut filtered = 0.0f64;
    for (i, out) in buf.iter_mut().skip(first).take(len).enumerate() {
        let t = i as f64 / rate;
        let osc = match tone.wave {
            Wave::Square { duty } => {
                if phase < f64::from(duty.clamp(0.05, 0.95)) {
                    1.0
                } else {
                    -1.0
                }
            }
            Wave::Saw => 2.0 * phase - 1.0,
            Wave::Triangle => 1.0 - 4.0 * (phase - 0.5).abs(),
            Wave::Sine => (TAU * phase).sin(),
            Wave::Noise => noise,
        };
        filtered += alpha * (osc - filtered);
        *out += filtered * tone.envelope(t) * f64::from(tone.gain);
        let before = phase;
        phase += tone.frequency(t) / rate;
        if phase >= 1.0 {
            phase -= phase.floor();
        }
        if matches!(tone.wave, Wave::Noise) && ((before < 0.5) != (phase < 0.5)) {
            noise = rng.next();
        }
    }
}

/// Renders `tones` mixed together to 16-bit mono at [`SAMPLE_RATE`], with
/// its peak at `peak` (0..=1) of full scale.
///
/// The result is as long as the longest tone (plus nothing: every
/// envelope ends at zero); empty only if every tone is.
pub fn render(tones: &[Tone], peak: f32) -> Vec<i16> {
    let over = OVERSAMPLE as usize;
    let seconds = tones
        .iter()
        .map(|t| t.start.max(0.0) + t.duration())
        .fold(0.0f32, f32::max);
    let len = (f64::from(seconds) * f64::from(SAMPLE_RATE)).ceil() as usize;
    let mut hi = vec![0.0f64; len * over];
    for tone in tones {
        render_tone(tone, &mut hi);
    }
    // Average down (a box filter: enough against the worst aliasing), then
    // a DC blocker (high-pass at about 20 Hz).
    let r = 1.0 - TAU * 20.0 / f64::from(SAMPLE_RATE);
    let (mut x1, mut y1) = (0.0f64, 0.0f64);
    let mut out: Vec<f64> = hi
        .chunks(over)
        .map(|c| {
            let x = c.iter().sum::<f64>() / over as f64;
            let y = x - x1 + r * y1;
            x1 = x;
            y1 = y;
            y
        })
        .collect();
    let max = out.iter().fold(0.0f64, |m, s| m.max(s.abs()));
    if max > 0.0 {
        let scale = f64::from(peak.clamp(0.0, 1.0)) * f64::from(i16::MAX) / max;
        for s in &mut out {
            *s *= scale;
        }
    }
    out.into_iter()
        .map(|s| s.round().clamp(f64::from(i16::MIN), f64::from(i16::MAX)) as i16)
        .collect()
}

/// Equal-tempered frequency of a MIDI note number (69 = A4 = 440 Hz).
pub fn note(midi: i32) -> f32 {
    (440.0 * ((f64::from(midi) - 69.0) / 12.0).exp2()) as f32
}

const SQUARE: Wave = Wave::Square { duty: 0.5 };
const PULSE: Wave = Wave::Square { duty: 0.25 };

/// The tones of an effect and its loudness (peak, fraction of full scale).
pub fn preset(effect: Effect) -> (Vec<Tone>, f32) {
    match effect {
        // A short rising square blip.
        Effect::Jump => (
            vec![Tone::new(SQUARE, 260.0, 0.06, 0.08)
                .slide_to(660.0)
                .lowpass(5000.0)],
            0.40,
        ),
        // A short low thud: dark noise, fast decay, under a low sine knock.
        Effect::Land => (
            vec![
                Tone::new(Wave::Noise, 1600.0, 0.0, 0.06)
                    .attack(0.001)
                    .lowpass(700.0)
                    .seed(7),
                Tone::new(Wave::Sine, 140.0, 0.0, 0.07)
                    .slide_to(60.0)
                    .attack(0.001)
                    .gain(0.8),
            ],
            0.35,
        ),
        // The classic two-note high arpeggio (B5 then E6).
        Effect::Coin => (
            vec![
                Tone::new(SQUARE, note(83), 0.05, 0.0).lowpass(7000.0),
                Tone::new(SQUARE, note(88), 0.06, 0.22)
                    .at(0.052)
                    .lowpass(7000.0),
            ],
            0.35,
        ),
        // A descending square with a click on top.
        Effect::Stomp => (
            vec![
                Tone::new(SQUARE, 700.0, 0.02, 0.12)
                    .slide_to(140.0)
                    .lowpass(4000.0),
                Tone::new(Wave::Noise, 5000.0, 0.0, 0.03)
                    .attack(0.001)
                    .gain(0.5)
                    .seed(11),
            ],
            0.45,
        ),
        // Noisy and descending: a harsh burst falling under a saw.
        Effect::Hurt => (
            vec![
                Tone::new(Wave::Noise, 3000.0, 0.05, 0.30)
                    .slide_to(300.0)
                    .attack(0.001)
                    .seed(23),
                Tone::new(Wave::Saw, 520.0, 0.05, 0.30)
                    .slide_to(70.0)
                    .lowpass(2500.0)
                    .gain(0.7),
            ],
            0.50,
        ),
        // Back at the checkpoint: a soft upward shimmer.
        Effect::Respawn => (
            vec![
                Tone::new(Wave::Triangle, note(72), 0.03, 0.05),
                Tone::new(Wave::Triangle, note(79), 0.03, 0.05).at(0.06),
                Tone::new(Wave::Triangle, note(84), 0.03, 0.12)
                    .at(0.12)
                    .vibrato(0.3, 9.0),
                Tone::new(Wave::Sine, note(96), 0.0, 0.20)
                    .at(0.12)
                    .gain(0.3),
            ],
            0.35,
        ),
        // Rising three-note (C5 E5 G5), the last one held a little.
        Effect::Checkpoint => (
            vec![
                Tone::new(PULSE, note(72), 0.06, 0.02).lowpass(6000.0),
                Tone::new(PULSE, note(76), 0.06, 0.02)
                    .at(0.085)
                    .lowpass(6000.0),
                Tone::new(PULSE, note(79), 0.10, 0.20)
                    .at(0.17)
                    .lowpass(6000.0)
                    .vibrato(0.2, 7.0),
            ],
            0.35,
        ),
        // A fast upward slide with a wobble.
        Effect::Spring => (
            vec![Tone::new(SQUARE, 200.0, 0.15, 0.06)
                .slide_to(1300.0)
                .vibrato(1.0, 18.0)
                .lowpass(5000.0)],
            0.40,
        ),
        // A short fanfare: G4 C5 E5 G5, then a held C6 with vibrato over a
        // low C.
        Effect::Goal => {
            let step = 0.09;
            let mut tones: Vec<Tone> = [67, 72, 76, 79]
                .iter()
                .enumerate()
                .map(|(i, &n)| {
                    Tone::new(SQUARE, note(n), 0.065, 0.015)
                        .at(step * i as f32)
                        .lowpass(6000.0)
                })
                .collect();
            tones.push(
                Tone::new(SQUARE, note(84), 0.30, 0.35)
                    .at(step * 4.0)
                    .vibrato(0.25, 6.0)
                    .lowpass(6000.0),
            );
            tones.push(
                Tone::new(Wave::Triangle, note(48), 0.30, 0.35)
                    .at(step * 4.0)
                    .gain(0.6),
            );
            (tones, 0.50)
        }
    }
}

/// The samples of `effect` (16-bit mono at [`SAMPLE_RATE`]).
pub fn effect(effect: Effect) -> Vec<i16> {
    let (tones, peak) = preset(effect);
    render(&tones, peak)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn envelope_starts_and_ends_at_zero() {
        let t = Tone::new(SQUARE, 440.0, 0.1, 0.1);
        assert_eq!(t.envelope(0.0), 0.0);
        assert_eq!(t.envelope(0.05), 1.0);
        assert!(t.envelope(f64::from(t.duration())) < 1e-9);
        assert_eq!(t.envelope(f64::from(t.duration()) + 1e-6), 0.0);
        assert!(t.envelope(0.15) > 0.0 && t.envelope(0.15) < 1.0);
    }

    #[test]
    fn slide_is_exponential_from_start_to_end() {
        let t = Tone::new(SQUARE, 100.0, 0.0, 1.0)
            .attack(0.0)
            .slide_to(400.0);
        assert!((t.frequency(0.0) - 100.0).abs() < 1e-9);
        assert!((t.frequency(0.5) - 200.0).abs() < 1e-6);
        assert!((t.frequency(1.0) - 400.0).abs() < 1e-6);
    }

    #[test]
    fn render_hits_the_requested_peak() {
        let s = render(&[Tone::new(Wave::Sine, 440.0, 0.1, 0.1)], 0.5);
        let peak = s.iter().map(|x| i32::from(*x).abs()).max().unwrap();
        assert!((peak - 16384).abs() <= 1, "peak {peak}");
        assert_eq!(s.len(), (0.202f64 * 44_100.0).ceil() as usize);
    }

    #[test]
    fn render_of_nothing_is_empty() {
        assert!(render(&[], 0.5).is_empty());
    }

    #[test]
    fn noise_is_seeded() {
        let a = render(&[Tone::new(Wave::Noise, 2000.0, 0.05, 0.0).seed(1)], 0.5);
        let b = render(&[Tone::new(Wave::Noise, 2000.0, 0.05, 0.0).seed(1)], 0.5);
        let c = render(&[Tone::new(Wave::Noise, 2000.0, 0.05, 0.0).seed(2)], 0.5);
        assert_eq!(a, b);
        assert_ne!(a, c);
    }

    #[test]
    fn a4_is_440() {
        assert!((note(69) - 440.0).abs() < 1e-3);
        assert!((note(81) - 880.0).abs() < 1e-3);
    }
}
