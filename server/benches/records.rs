//! Record write latency: 256 players finishing at once, as the records
//! writer sees them (the rooms' queue, batches, one transaction each, the
//! answer after the commit).
//!
//! `cargo bench -p ledge-server --bench records` prints a Markdown table
//! (the one in docs/PERFORMANCE.md, "Records"): for each store, the time
//! from a run's submission to its player's answer, p50 / p99 / max over
//! `ROUNDS` rounds of `PLAYERS` runs submitted together, and the runs a
//! second. SQLite is a file in a temporary directory (WAL, a sync at every
//! commit); PostgreSQL is measured when `LEDGE_BENCH_POSTGRES` holds a
//! URL (e.g. a throwaway cluster's).

use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use ledge_server::records::writer::WriterMetrics;
use ledge_server::records::{FinishedRun, RecordStore, RecordsHandle, RecordsTarget};

/// Players finishing at once.
const PLAYERS: usize = 256;
/// Rounds of them.
const ROUNDS: usize = 20;

fn run(round: usize, i: usize) -> FinishedRun {
    FinishedRun {
        key: format!("bench/{round}/{i}/{}", std::process::id()),
        level_hash: "be".repeat(32),
        level_name: "bench".into(),
        player: format!("player-{i}"),
        ticks: 600 + (i as u32 * 7919 + round as u32 * 104_729) % 600,
        tick_rate: 60,
        deaths: 0,
        coins: 0,
        place: 1,
        finished_at_ms: 0,
        replay_id: None,
    }
}

/// p-th percentile (0..=100) of sorted `v`.
fn percentile(v: &[Duration], p: usize) -> Duration {
    v[((v.len() - 1) * p / 100).min(v.len() - 1)]
}

async fn measure(name: &str, target: RecordsTarget) {
    let store = match RecordStore::open(&target).await {
        Ok(Some(store)) => store,
        Ok(None) => return,
        Err(e) => {
            println!("| {name} | not measured: {e} | | | |");
            return;
        }
    };
    let (handle, task) = RecordsHandle::spawn(store.clone(), WriterMetrics::default());
    let latencies = Arc::new(Mutex::new(Vec::with_capacity(PLAYERS * ROUNDS)));
    let started = Instant::now();
    for round in 0..ROUNDS {
        let (done_tx, mut done_rx) = tokio::sync::mpsc::unbounded_channel();
        let submitted = Instant::now();
        for i in 0..PLAYERS {
            let (latencies, done) = (latencies.clone(), done_tx.clone());
            handle.submit(
                run(round, i),
                Box::new(move |result| {
                    assert!(result.is_ok(), "{result:?}");
                    latencies
                        .lock()
                        .unwrap_or_else(std::sync::PoisonError::into_inner)
                        .push(submitted.elapsed());
                    let _ = done.send(());
                }),
            );
        }
        for _ in 0..PLAYERS {
            done_rx.recv().await.expect("every run answered");
        }
    }
    let secs = started.elapsed().as_secs_f64();
    drop(handle);
    let _ = task.await;
    store.close().await;
    let mut v = latencies
        .lock()
        .unwrap_or_else(std::sync::PoisonError::into_inner)
        .clone();
    v.sort();
    let ms = |d: Duration| d.as_secs_f64() * 1e3;
    println!(
        "| {name} | {:.1} | {:.1} | {:.1} | {:.0} |",
        ms(percentile(&v, 50)),
        ms(percentile(&v, 99)),
        ms(*v.last().expect("runs")),
        v.len() as f64 / secs
    );
}

fn main() {
    let runtime = tokio::runtime::Builder::new_multi_thread()
        .worker_threads(2)
        .enable_all()
        .build()
        .expect("a runtime");
    runtime.block_on(async {
        println!(
            "{PLAYERS} runs submitted at once, {ROUNDS} rounds: time from submission to the \
             player's answer (after the commit), ms"
        );
        println!();
        println!("| store | p50 | p99 | max | runs/s |");
        println!("|---|---|---|---|---|");
        let dir = tempfile::tempdir().expect("a temporary directory");
        measure(
            "SQLite (file, WAL, synchronous = FULL)",
            RecordsTarget::Sqlite(dir.path().join("bench.sqlite")),
        )
        .await;
        match std::env::var("LEDGE_BENCH_POSTGRES") {
            Ok(url) => measure("PostgreSQL 15 (local)", RecordsTarget::Url(url)).await,
            Err(_) => println!("| PostgreSQL | set LEDGE_BENCH_POSTGRES=postgres://... | | | |"),
        }
    });
}
