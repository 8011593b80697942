//! Tests of the sound: every effect is synthesized and sounds like
//! something, the synthesizer is deterministic, the mixer limits voices
//! and scales and saturates correctly, and the client's audio starts (or
//! reports why it cannot) on a machine without a sound card, without
//! failing or hanging.

use std::sync::Arc;
use std::time::{Duration, Instant};

use super::{
    alsa, synth, Audio, AudioStatus, Effect, Mixer, Sounds, MAX_VOICES, RETRIGGER_SAMPLES,
    SAMPLE_RATE,
};

fn peak(s: &[i16]) -> i32 {
    s.iter().map(|x| i32::from(*x).abs()).max().unwrap_or(0)
}

#[test]
fn every_effect_is_generated_and_audible() {
    let sounds = Sounds::generate();
    for e in Effect::ALL {
        let s = sounds.get(e);
        let d = sounds.duration(e);
        assert!(
            d >= Duration::from_millis(30) && d <= Duration::from_secs(2),
            "{}: {d:?} long",
            e.name()
        );
        let p = peak(s);
        // Loud enough to hear, with headroom for mixing.
        assert!(p > 5_000, "{}: peak {p} is nearly silent", e.name());
        assert!(p <= i32::from(i16::MAX), "{}: peak {p}", e.name());
        // No DC offset: the mean is small against the peak.
        let mean = s.iter().map(|x| f64::from(*x)).sum::<f64>() / s.len() as f64;
        assert!(
            mean.abs() < 0.02 * f64::from(p),
            "{}: mean {mean} against peak {p}",
            e.name()
        );
        // Starts and ends quietly (no click).
        let edge = 0.1 * f64::from(p);
        assert!(
            f64::from(s[0].unsigned_abs()) < edge,
            "{}: starts loud",
            e.name()
        );
        assert!(
            f64::from(s[s.len() - 1].unsigned_abs()) < edge,
            "{}: ends loud",
            e.name()
        );
    }
}

#[test]
fn effects_differ_from_each_other() {
    let sounds = Sounds::generate();
    for (i, a) in Effect::ALL.iter().enumerate() {
        for b in &Effect::ALL[i + 1..] {
            assert_ne!(sounds.get(*a), sounds.get(*b), "{a:?} and {b:?}");
        }
    }
}

#[test]
fn effects_have_their_character() {
    let sounds = Sounds::generate();
    let d = |e| sounds.duration(e);
    // Land and jump are short; the goal fanfare is the longest.
    assert!(d(Effect::Land) <= Duration::from_millis(120));
    assert!(d(Effect::Jump) <= Duration::from_millis(250));
    for e in Effect::ALL {
        assert!(d(e) <= d(Effect::Goal), "{e:?} longer than the goal");
    }
    // Jump rises: more zero crossings (higher pitch) at the end than at
    // the start.
    let crossings = |s: &[i16]| s.windows(2).filter(|w| (w[0] < 0) != (w[1] < 0)).count();
    let jump = sounds.get(Effect::Jump);
    let q = jump.len() / 4;
    assert!(crossings(&jump[3 * q..]) > crossings(&jump[..q]));
    // Stomp falls.
    let stomp = sounds.get(Effect::Stomp);
    let q = stomp.len() / 4;
    assert!(crossings(&stomp[2 * q..3 * q]) < crossings(&stomp[..q]));
}

#[test]
fn the_synthesizer_is_deterministic() {
    let a = Sounds::generate();
    let b = Sounds::generate();
    assert_eq!(a, b);
    for e in Effect::ALL {
        assert_eq!(synth::effect(e), a.get(e), "{e:?}");
    }
}

#[test]
fn audio_can_be_shared_between_threads() {
    fn send_sync<T: Send + Sync>() {}
    send_sync::<Audio>();
    send_sync::<Sounds>();
    send_sync::<Mixer>();
}

#[test]
fn effect_metadata_is_consistent() {
    for (i, e) in Effect::ALL.iter().enumerate() {
        assert_eq!(e.index(), i);
        assert!(!e.name().is_empty());
    }
}

fn loud(_: Effect) -> Vec<i16> {
    vec![30_000; 1000]
}

#[test]
fn mixing_saturates_instead_of_wrapping() {
    let mut m = Mixer::new(Arc::new(Sounds::from_fn(loud)), MAX_VOICES);
    m.play(Effect::Jump);
    m.play(Effect::Coin);
    let mut out = [0i16; 64];
    m.fill(&mut out, 1.0, false);
    assert!(out.iter().all(|&s| s == i16::MAX), "{out:?}");

    let mut m = Mixer::new(
        Arc::new(Sounds::from_fn(|_| vec![-30_000; 1000])),
        MAX_VOICES,
    );
    m.play(Effect::Jump);
    m.play(Effect::Coin);
    m.fill(&mut out, 1.0, false);
    assert!(out.iter().all(|&s| s == i16::MIN), "{out:?}");
}

#[test]
fn mixing_adds_voices_and_scales_by_volume() {
    let sounds = Arc::new(Sounds::from_fn(|e| vec![100 * (e.index() as i16 + 1); 500]));
    let mut m = Mixer::new(sounds, MAX_VOICES);
    m.play(Effect::Jump); // 100
    m.play(Effect::Land); // 200
    let mut out = [0i16; 100];
    m.fill(&mut out, 1.0, false);
    assert!(out.iter().all(|&s| s == 300));
    m.fill(&mut out, 0.5, false);
    assert!(out.iter().all(|&s| s == 150));
    // Out of range volumes are clamped.
    m.fill(&mut out, 7.0, false);
    assert!(out.iter().all(|&s| s == 300));
}

#[test]
fn volume_zero_and_mute_are_silent() {
    let sounds = Arc::new(Sounds::generate());
    for (volume, muted) in [(0.0, false), (1.0, true), (-1.0, false), (f32::NAN, false)] {
        let mut m = Mixer::new(Arc::clone(&sounds), MAX_VOICES);
        for e in Effect::ALL {
            m.play(e);
        }
        let mut out = [1i16; 4096];
        m.fill(&mut out, volume, muted);
        assert!(
            out.iter().all(|&s| s == 0),
            "volume {volume}, muted {muted}"
        );
        // Muted voices still advance.
        assert!(m.active() > 0);
    }
}

#[test]
fn voices_are_limited_and_the_oldest_is_replaced() {
    let mut m = Mixer::new(Arc::new(Sounds::from_fn(loud)), 3);
    m.play(Effect::Jump);
    m.play(Effect::Land);
    m.play(Effect::Coin);
    m.play(Effect::Stomp);
    assert_eq!(m.active(), 3);
    assert_eq!(
        m.playing().collect::<Vec<_>>(),
        [Effect::Land, Effect::Coin, Effect::Stomp]
    );
    let mut m = Mixer::new(Arc::new(Sounds::generate()), MAX_VOICES);
    for e in Effect::ALL {
        m.play(e);
    }
    assert_eq!(m.active(), MAX_VOICES);
}

#[test]
fn an_effect_retriggered_at_once_is_not_layered() {
    let sounds = Arc::new(Sounds::from_fn(|_| vec![1000; SAMPLE_RATE as usize]));
    let mut m = Mixer::new(sounds, MAX_VOICES);
    for _ in 0..8 {
        m.play(Effect::Coin);
    }
    assert_eq!(m.active(), 1);
    let mut out = vec![0i16; RETRIGGER_SAMPLES];
    m.fill(&mut out, 1.0, false);
    assert!(out.iter().all(|&s| s == 1000));
    m.play(Effect::Coin);
    assert_eq!(m.active(), 2);
}

#[test]
fn finished_voices_end() {
    let sounds = Arc::new(Sounds::from_fn(|_| vec![500; 300]));
    let mut m = Mixer::new(sounds, MAX_VOICES);
    m.play(Effect::Goal);
    let mut out = [0i16; 512];
    m.fill(&mut out, 1.0, false);
    assert!(out[..300].iter().all(|&s| s == 500));
    assert!(out[300..].iter().all(|&s| s == 0));
    assert_eq!(m.active(), 0);
}

#[test]
fn a_missing_library_is_an_error_naming_it() {
    let err = alsa::open("libdefinitely-missing.so.2").unwrap_err();
    assert!(
        err.to_string().contains("libdefinitely-missing.so.2"),
        "{err}"
    );
    let audio = Audio::start_with("libdefinitely-missing.so.2", alsa::DEFAULT_DEVICE);
    match audio.status() {
        AudioStatus::Off { reason } => {
            assert!(reason.contains("libdefinitely-missing.so.2"), "{reason}")
        }
        s => panic!("{s:?}"),
    }
    for e in Effect::ALL {
        audio.play(e);
    }
}

#[test]
fn a_missing_device_is_off_with_a_reason() {
    // The real library (if this machine has it) and a device that does not
    // exist in any ALSA configuration.
    let audio = Audio::start_with(alsa::LIBRARY, "ledge_no_such_device");
    let AudioStatus::Off { reason } = audio.status() else {
        panic!("{:?}", audio.status());
    };
    // Names the device, or (on a machine without ALSA) the library.
    assert!(
        reason.contains("ledge_no_such_device") || reason.contains(alsa::LIBRARY),
        "{reason}"
    );
    assert!(!audio.status().is_playing());
    audio.play(Effect::Coin);
}

#[test]
fn plays_on_alsas_null_device() {
    // ALSA's built-in `null` PCM needs no sound card: the whole playing
    // path (open, parameters, the mixer thread writing, stop, close) runs.
    if let Err(e) = alsa::open(alsa::LIBRARY) {
        eprintln!("skipped: {e}");
        return;
    }
    let t0 = Instant::now();
    let audio = Audio::start_with(alsa::LIBRARY, "null");
    assert_eq!(
        audio.status(),
        AudioStatus::Playing {
            device: "ALSA null".to_owned()
        }
    );
    for e in Effect::ALL {
        audio.play(e);
    }
    std::thread::sleep(Duration::from_millis(100));
    audio.set_volume(0.5);
    audio.set_muted(true);
    for e in Effect::ALL {
        audio.play(e);
    }
    std::thread::sleep(Duration::from_millis(50));
    assert!(audio.status().is_playing(), "{}", audio.status());
    drop(audio);
    assert!(t0.elapsed() < Duration::from_secs(2), "{:?}", t0.elapsed());
}

#[test]
fn start_play_and_drop_return_promptly_without_a_sound_card() {
    let t0 = Instant::now();
    let audio = Audio::start();
    let status = audio.status();
    eprintln!("Audio::start(): {status}");
    match &status {
        AudioStatus::Playing { device } => assert!(!device.is_empty()),
        AudioStatus::Off { reason } => assert!(!reason.is_empty()),
    }
    for _ in 0..10 {
        for e in Effect::ALL {
            audio.play(e);
        }
    }
    audio.set_volume(0.3);
    audio.toggle_mute();
    drop(audio);
    // A behaviour check (no hang), not a benchmark.
    assert!(t0.elapsed() < Duration::from_secs(2), "{:?}", t0.elapsed());
}

#[test]
fn volume_and_mute_settings() {
    for audio in [Audio::disabled("test"), Audio::start()] {
        assert_eq!(audio.volume(), 1.0);
        assert!(!audio.is_muted());
        audio.set_volume(0.25);
        assert_eq!(audio.volume(), 0.25);
        audio.set_volume(3.0);
        assert_eq!(audio.volume(), 1.0);
        audio.set_volume(-1.0);
        assert_eq!(audio.volume(), 0.0);
        audio.set_volume(f32::NAN);
        assert_eq!(audio.volume(), 0.0);
        assert!(audio.toggle_mute());
        assert!(audio.is_muted());
        assert!(!audio.toggle_mute());
        audio.set_muted(true);
        assert!(audio.is_muted());
    }
    assert_eq!(
        Audio::disabled("no sound card").status(),
        AudioStatus::Off {
            reason: "no sound card".to_owned()
        }
    );
    assert_eq!(Audio::disabled("x").status().to_string(), "sound off: x");
}
