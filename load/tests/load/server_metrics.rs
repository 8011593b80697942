//! The load benchmark reads the real server's metrics text: the parser and
//! the window quantiles are checked against `ledge_server::metrics` itself,
//! with known tick durations observed between two scrapes.

use ledge_load::prom::Scrape;
use ledge_server::metrics::{encode, Channel, Metrics, RoomLabel};

/// Deterministic tick durations from 60 µs to ~3 ms, skewed to the low end.
fn durations(n: u32, seed: u32) -> Vec<f64> {
    (0..n)
        .map(|i| {
            let x = f64::from(i.wrapping_mul(2_654_435_761).wrapping_add(seed) % 100_000) / 1e5;
            60e-6 + x.powi(4) * 3e-3
        })
        .collect()
}

fn exact(mut values: Vec<f64>, q: f64) -> f64 {
    values.sort_by(f64::total_cmp);
    values[(q * values.len() as f64).ceil() as usize - 1]
}

#[test]
fn window_quantiles_from_two_scrapes_match_the_observed_ticks() {
    let (metrics, registry) = Metrics::new();
    // Before the window: slow ticks that must not count.
    for d in durations(2_000, 1) {
        metrics.tick_duration_fine.observe(d * 10.0);
    }
    let room = |name: &str| RoomLabel { room: name.into() };
    metrics
        .missed_ticks
        .get_or_create(&room("room-1"))
        .inc_by(5);
    let before = Scrape::parse(&encode(&registry)).unwrap();

    let window = durations(20_000, 7);
    for &d in &window {
        metrics.tick_duration_fine.observe(d);
    }
    metrics
        .missed_ticks
        .get_or_create(&room("room-2"))
        .inc_by(2);
    let client = metrics.client(3);
    metrics.received(&client, Channel::Datagram, 1_000);
    metrics.sent(&client, Channel::Stream, 4_000);
    let after = Scrape::parse(&encode(&registry)).unwrap();

    let name = "ledge_tick_duration_fine_seconds";
    let h = after
        .histogram(name)
        .unwrap()
        .since(&before.histogram(name).unwrap())
        .unwrap();
    assert_eq!(h.total(), window.len() as u64);
    for q in [0.5, 0.99] {
        let got = h.quantile(q).unwrap();
        let want = exact(window.clone(), q);
        assert!(
            (want / 1.045..=want * 1.045).contains(&got),
            "q {q}: {got} vs {want}"
        );
    }
    let max = window.iter().copied().fold(0.0, f64::max);
    let bound = h.max_bound().unwrap();
    assert!(bound >= max && bound <= max * 1.045, "{bound} vs {max}");
    let sum = after.sum(&format!("{name}_sum")) - before.sum(&format!("{name}_sum"));
    let want: f64 = window.iter().sum();
    assert!((sum - want).abs() < 1e-6 * want.max(1.0), "{sum} vs {want}");

    let delta = |n: &str| after.sum(n) - before.sum(n);
    assert_eq!(delta("ledge_missed_ticks_total"), 2.0);
    assert_eq!(after.sum("ledge_missed_ticks_total"), 7.0);
    assert_eq!(delta("ledge_bytes_in_total"), 1_000.0);
    assert_eq!(delta("ledge_bytes_out_total"), 4_000.0);
    assert_eq!(
        after.get("ledge_bytes_out_total", "channel", "Stream"),
        Some(4_000.0)
    );
    // The lateness histogram is served too, with the same fine buckets.
    let late = after.histogram("ledge_tick_lateness_seconds").unwrap();
    assert_eq!(late.bounds(), h.bounds());
    assert_eq!(late.total(), 0);
}
