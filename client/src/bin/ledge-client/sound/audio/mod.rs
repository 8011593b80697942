//! Sound effects: synthesized at start, played through ALSA loaded at run
//! time, and never a reason for the client to fail.
//!
//! * [`Effect`]: what can be played; [`Sounds`]: their samples, built once
//!   by the synthesizer ([`synth`]); no audio files ship with the client.
//! * [`Audio`]: the player. [`Audio::start`] never fails: when ALSA is not
//!   installed, no device opens (containers, CI, Xvfb) or anything else
//!   goes wrong, sound is off ([`AudioStatus::Off`] says why, in one log
//!   line too) and [`Audio::play`] does nothing. Nothing here panics or
//!   blocks the caller: `play` is a `try_send` on a bounded channel (a full
//!   channel drops the sound), volume and mute are atomics.
//! * A mixer thread mixes up to [`MAX_VOICES`] effects ([`Mixer`], pure and
//!   tested without a device) into small buffers and writes them to the
//!   device ([`alsa`]). Dropping the [`Audio`] stops it and joins it,
//!   waiting at most [`STOP_TIMEOUT`].
//!
//! The window maps game events to effects ([`crate::sound::cues`]) and owns the
//! mute key and the volume setting; this module only offers the calls. Only
//! the window plays sound, so it is part of the front end, not of the
//! headless library.

#[cfg(not(target_arch = "wasm32"))]
pub mod alsa;
mod effect;
pub mod synth;

use std::fmt;
use std::sync::atomic::{AtomicBool, AtomicU32, Ordering};
#[cfg(not(target_arch = "wasm32"))]
use std::sync::mpsc::{self, Receiver, RecvTimeoutError};
use std::sync::mpsc::{SyncSender, TrySendError};
use std::sync::{Arc, Mutex, PoisonError};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

pub use effect::Effect;
pub use synth::SAMPLE_RATE;

/// The samples of every effect: 16-bit mono at [`SAMPLE_RATE`].
#[derive(Clone, PartialEq, Eq)]
pub struct Sounds {
    samples: Vec<Vec<i16>>,
}

impl fmt::Debug for Sounds {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let mut map = f.debug_map();
        for e in Effect::ALL {
            map.entry(&e.name(), &self.get(e).len());
        }
        map.finish()
    }
}

impl Sounds {
    /// Synthesizes every effect ([`synth::effect`]); deterministic, a few
    /// milliseconds of work.
    pub fn generate() -> Sounds {
        Sounds::from_fn(synth::effect)
    }

    /// Sounds made by `f` for each effect (tests, or other sources).
    pub fn from_fn(mut f: impl FnMut(Effect) -> Vec<i16>) -> Sounds {
        Sounds {
            samples: Effect::ALL.iter().map(|&e| f(e)).collect(),
        }
    }

    /// The samples of `effect`.
    pub fn get(&self, effect: Effect) -> &[i16] {
        &self.samples[effect.index()]
    }

    /// The duration of `effect`.
    #[cfg(test)]
    pub fn duration(&self, effect: Effect) -> Duration {
        Duration::from_secs_f64(self.get(effect).len() as f64 / f64::from(SAMPLE_RATE))
    }
}

/// How many effects play at once; starting one more replaces the oldest.
pub const MAX_VOICES: usize = 8;

/// An effect started again within this many samples (about 30 ms) of the
/// same effect is not layered on it: eight coins in a tick play as one.
pub const RETRIGGER_SAMPLES: usize = SAMPLE_RATE as usize * 3 / 100;

/// Frames per buffer the mixer thread writes (about 5.8 ms).
pub const BUFFER_FRAMES: usize = 256;

/// Device buffering asked of ALSA, µs.
pub const LATENCY_US: u32 = 40_000;

/// How long [`Audio::start`] waits for the device to open.
pub const OPEN_TIMEOUT: Duration = Duration::from_secs(1);

/// How long dropping an [`Audio`] waits for its thread.
pub const STOP_TIMEOUT: Duration = Duration::from_millis(500);

/// Play requests queued for the mixer thread; more are dropped.
#[cfg(not(target_arch = "wasm32"))]
const QUEUE: usize = 32;

#[derive(Debug, Clone, Copy)]
struct Voice {
    effect: Effect,
    pos: usize,
}

/// Mixes playing effects into sample buffers: the mixer thread's work,
/// without a device (pure, so it is tested directly).
#[derive(Debug, Clone)]
pub struct Mixer {
    sounds: Arc<Sounds>,
    voices: Vec<Voice>,
    max_voices: usize,
}

impl Mixer {
    /// A mixer of `sounds` playing at most `max_voices` (at least 1) at once.
    pub fn new(sounds: Arc<Sounds>, max_voices: usize) -> Mixer {
        let max_voices = max_voices.max(1);
        Mixer {
            sounds,
            voices: Vec::with_capacity(max_voices),
            max_voices,
        }
    }

    /// Starts `effect`. With every voice busy the oldest is replaced; the
    /// same effect started less than [`RETRIGGER_SAMPLES`] ago is not
    /// layered again.
    pub fn play(&mut self, effect: Effect) {
        if self.sounds.get(effect).is_empty() {
            return;
        }
        if self
            .voices
            .iter()
            .any(|v| v.effect == effect && v.pos < RETRIGGER_SAMPLES)
        {
            return;
        }
        if self.voices.len() >= self.max_voices {
            // Voices are kept in start order: the first is the oldest.
            self.voices.remove(0);
        }
        self.voices.push(Voice { effect, pos: 0 });
    }

    /// How many effects are playing.
    #[cfg(test)]
    pub fn active(&self) -> usize {
        self.voices.len()
    }

    /// The effects playing, oldest first.
    #[cfg(test)]
    pub fn playing(&self) -> impl Iterator<Item = Effect> + '_ {
        self.voices.iter().map(|v| v.effect)
    }

    /// Fills `out` with the next samples of every voice, summed, scaled by
    /// `volume` (clamped to 0..=1) and saturated to 16 bits; silence if
    /// `muted` (voices still advance, so unmuting resumes the present, not
    /// the past). Finished voices are removed.
    pub fn fill(&mut self, out: &mut [i16], volume: f32, muted: bool) {
        let volume = if muted || volume.is_nan() {
            0.0
        } else {
            volume.clamp(0.0, 1.0)
        };
        let mut acc = [0i32; BUFFER_FRAMES];
        for chunk in out.chunks_mut(BUFFER_FRAMES) {
            let acc = &mut acc[..chunk.len()];
            acc.fill(0);
            for v in &mut self.voices {
                let samples = self.sounds.get(v.effect);
                let rest = samples.get(v.pos..).unwrap_or(&[]);
                for (a, s) in acc.iter_mut().zip(rest) {
                    *a += i32::from(*s);
                }
                v.pos += chunk.len();
            }
            for (o, a) in chunk.iter_mut().zip(acc.iter()) {
                let scaled = if volume >= 1.0 {
                    *a
                } else {
                    (*a as f32 * volume).round() as i32
                };
                *o = scaled.clamp(i32::from(i16::MIN), i32::from(i16::MAX)) as i16;
            }
            let sounds = &self.sounds;
            self.voices.retain(|v| v.pos < sounds.get(v.effect).len());
        }
    }
}

/// Whether sound is on, for the window to show.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum AudioStatus {
    /// Effects are played on `device`.
    Playing {
        /// The library and device, e.g. `ALSA default`.
        device: String,
    },
    /// No sound, and why.
    Off {
        /// Why (one line, for the window and the log).
        reason: String,
    },
}

impl AudioStatus {
    /// True when effects are played.
    #[cfg(test)]
    pub fn is_playing(&self) -> bool {
        matches!(self, AudioStatus::Playing { .. })
    }
}

impl fmt::Display for AudioStatus {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            AudioStatus::Playing { device } => write!(f, "sound on ({device})"),
            AudioStatus::Off { reason } => write!(f, "sound off: {reason}"),
        }
    }
}

/// State shared by the [`Audio`] handle and its mixer thread.
#[derive(Debug)]
struct Shared {
    /// The volume's `f32` bits.
    volume: AtomicU32,
    muted: AtomicBool,
    stop: AtomicBool,
    status: Mutex<AudioStatus>,
}

impl Shared {
    fn new(status: AudioStatus) -> Shared {
        Shared {
            volume: AtomicU32::new(1.0f32.to_bits()),
            muted: AtomicBool::new(false),
            stop: AtomicBool::new(false),
            status: Mutex::new(status),
        }
    }

    #[cfg(not(target_arch = "wasm32"))]
    fn set_status(&self, status: AudioStatus) {
        *self.status.lock().unwrap_or_else(PoisonError::into_inner) = status;
    }

    fn status(&self) -> AudioStatus {
        self.status
            .lock()
            .unwrap_or_else(PoisonError::into_inner)
            .clone()
    }
}

/// The mixer thread, while it runs.
#[derive(Debug)]
struct Worker {
    tx: SyncSender<Effect>,
    thread: JoinHandle<()>,
}

/// The sound effect player. See the [module documentation](self).
///
/// Volume and mute work the same whether sound is on or off (so a setting
/// is kept), but only change what is heard while it is on.
#[derive(Debug)]
pub struct Audio {
    shared: Arc<Shared>,
    worker: Option<Worker>,
}

impl Audio {
    /// Starts sound on ALSA's default device. Never fails: without ALSA or
    /// a device the result is [`Audio::disabled`] with the reason (logged
    /// once at info level). Waits at most [`OPEN_TIMEOUT`] for the device.
    #[cfg(not(target_arch = "wasm32"))]
    pub fn start() -> Audio {
        Audio::start_with(alsa::LIBRARY, alsa::DEFAULT_DEVICE)
    }

    /// In a browser: sound is off (the page's Web Audio is not wired up).
    #[cfg(target_arch = "wasm32")]
    pub fn start() -> Audio {
        Audio::disabled("the browser client has no sound yet")
    }

    /// [`Audio::start`] with another ALSA library file name or PCM device
    /// (tests; a device chosen by the user).
    #[cfg(not(target_arch = "wasm32"))]
    pub fn start_with(library: &str, device: &str) -> Audio {
        let shared = Arc::new(Shared::new(AudioStatus::Off {
            reason: "starting".to_owned(),
        }));
        let (tx, rx) = mpsc::sync_channel::<Effect>(QUEUE);
        let (opened_tx, opened_rx) = mpsc::sync_channel::<Result<String, String>>(1);
        let thread = {
            let shared = Arc::clone(&shared);
            let library = library.to_owned();
            let device = device.to_owned();
            std::thread::Builder::new()
                .name("ledge-audio".to_owned())
                .spawn(move || mixer_thread(&library, &device, &shared, &rx, opened_tx))
        };
        let thread = match thread {
            Ok(thread) => thread,
            Err(e) => return Audio::disabled(format!("no audio thread: {e}")),
        };
        let reason = match opened_rx.recv_timeout(OPEN_TIMEOUT) {
            Ok(Ok(device)) => {
                // The thread has set the status (before any write could
                // turn it off again).
                tracing::info!("sound on: {device}");
                return Audio {
                    shared,
                    worker: Some(Worker { tx, thread }),
                };
            }
            Ok(Err(reason)) => reason,
            Err(RecvTimeoutError::Timeout) => {
                format!("the audio device did not open within {OPEN_TIMEOUT:?}")
            }
            Err(RecvTimeoutError::Disconnected) => "the audio thread ended".to_owned(),
        };
        // The thread has given up (or gives up when its slow open returns):
        // stop it, and join it if it ends within STOP_TIMEOUT.
        let mut audio = Audio {
            shared,
            worker: Some(Worker { tx, thread }),
        };
        audio.shutdown();
        audio.shared.set_status(AudioStatus::Off {
            reason: reason.clone(),
        });
        tracing::info!("sound off: {reason}");
        audio
    }

    /// An [`Audio`] that plays nothing, with the reason to show. Logs
    /// nothing (the caller chose it).
    pub fn disabled(reason: impl Into<String>) -> Audio {
        Audio {
            shared: Arc::new(Shared::new(AudioStatus::Off {
                reason: reason.into(),
            })),
            worker: None,
        }
    }

    /// Plays `effect` (no-op while sound is off; dropped if the mixer is
    /// behind by more than a few dozen requests). Never blocks.
    pub fn play(&self, effect: Effect) {
        if let Some(worker) = &self.worker {
            match worker.tx.try_send(effect) {
                Ok(()) | Err(TrySendError::Disconnected(_)) => {}
                Err(TrySendError::Full(_)) => {
                    tracing::debug!("audio queue full: {} dropped", effect.name());
                }
            }
        }
    }

    /// Sets the volume, clamped to 0.0..=1.0 (linear gain; NaN is ignored).
    pub fn set_volume(&self, volume: f32) {
        if !volume.is_nan() {
            self.shared
                .volume
                .store(volume.clamp(0.0, 1.0).to_bits(), Ordering::Relaxed);
        }
    }

    /// The volume, 0.0..=1.0 (1.0 at start).
    #[cfg(test)]
    pub fn volume(&self) -> f32 {
        f32::from_bits(self.shared.volume.load(Ordering::Relaxed))
    }

    /// Mutes or unmutes.
    pub fn set_muted(&self, muted: bool) {
        self.shared.muted.store(muted, Ordering::Relaxed);
    }

    /// Flips mute; returns whether sound is now muted.
    pub fn toggle_mute(&self) -> bool {
        !self.shared.muted.fetch_xor(true, Ordering::Relaxed)
    }

    /// Whether sound is muted (false at start).
    pub fn is_muted(&self) -> bool {
        self.shared.muted.load(Ordering::Relaxed)
    }

    /// Whether sound is on, and if not, why. Turns to
    /// [`AudioStatus::Off`] if the device fails while playing.
    pub fn status(&self) -> AudioStatus {
        self.shared.status()
    }

    /// Stops the mixer thread and joins it, waiting at most
    /// [`STOP_TIMEOUT`] (past that it is left to end on its own).
    fn shutdown(&mut self) {
        self.shared.stop.store(true, Ordering::Relaxed);
        if let Some(worker) = self.worker.take() {
            drop(worker.tx);
            // Join only once the thread has finished, so this never waits
            // on a device stuck inside ALSA for longer than STOP_TIMEOUT.
            // (It sees `stop` within one 20 ms device wait.)
            let deadline = Instant::now() + STOP_TIMEOUT;
            while !worker.thread.is_finished() && Instant::now() < deadline {
                std::thread::sleep(Duration::from_millis(1));
            }
            if worker.thread.is_finished() {
                let _ = worker.thread.join();
            } else {
                tracing::warn!("the audio thread did not stop within {STOP_TIMEOUT:?}");
            }
        }
    }
}

impl Drop for Audio {
    fn drop(&mut self) {
        self.shutdown();
    }
}

/// The mixer thread: loads ALSA, opens the device, reports the outcome on
/// `opened`, then mixes and writes until told to stop.
#[cfg(not(target_arch = "wasm32"))]
fn mixer_thread(
    library: &str,
    device: &str,
    shared: &Shared,
    rx: &Receiver<Effect>,
    opened: SyncSender<Result<String, String>>,
) {
    let lib = match alsa::open(library) {
        Ok(lib) => lib,
        Err(e) => {
            let _ = opened.send(Err(e.to_string()));
            return;
        }
    };
    lib.log_errors_on_this_thread();
    let mut pcm = match lib.open_pcm(device, SAMPLE_RATE, LATENCY_US) {
        Ok(pcm) => pcm,
        Err(e) => {
            let _ = opened.send(Err(format!("no audio device: {e}")));
            return;
        }
    };
    // Start() may have given up waiting: then it has set `stop`.
    if shared.stop.load(Ordering::Relaxed) {
        return;
    }
    let name = format!("ALSA {}", pcm.device());
    shared.set_status(AudioStatus::Playing {
        device: name.clone(),
    });
    if opened.send(Ok(name)).is_err() {
        return;
    }
    let mut mixer = Mixer::new(Arc::new(Sounds::generate()), MAX_VOICES);
    let mut buf = [0i16; BUFFER_FRAMES];
    let buffer_time = Duration::from_secs_f64(BUFFER_FRAMES as f64 / f64::from(SAMPLE_RATE));
    // Frames written since the device last made us wait: a device that
    // never does (ALSA's `null`) is paced by the clock instead of being
    // fed as fast as this loop runs.
    let mut unpaced = 0usize;
    while !shared.stop.load(Ordering::Relaxed) {
        while let Ok(effect) = rx.try_recv() {
            mixer.play(effect);
        }
        let volume = f32::from_bits(shared.volume.load(Ordering::Relaxed));
        let muted = shared.muted.load(Ordering::Relaxed);
        mixer.fill(&mut buf, volume, muted);
        match pcm.write(&buf, &shared.stop) {
            Ok(true) => unpaced = 0,
            Ok(false) => {
                unpaced += buf.len();
                if unpaced > SAMPLE_RATE as usize / 2 {
                    std::thread::sleep(buffer_time);
                }
            }
            Err(e) => {
                let reason = format!("the audio device failed: {e}");
                tracing::warn!("sound off: {reason}");
                shared.set_status(AudioStatus::Off { reason });
                return;
            }
        }
    }
}

#[cfg(test)]
mod tests;
