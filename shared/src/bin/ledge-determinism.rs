//! Runs the warm-up room with the scripted inputs and prints only the final
//! state hash (16 hex digits), for comparing builds:
//!
//! `cargo run --release -p ledge-shared --bin ledge-determinism -- 100000`
//!
//! A binary rather than an example: examples link every dev-dependency
//! (criterion, proptest, the level importers), and the determinism test
//! builds this in release mode (`tests/simulation/determinism.rs`).

fn main() {
    let ticks: u64 = match std::env::args().nth(1) {
        None => 100_000,
        Some(a) => match a.parse() {
            Ok(t) => t,
            Err(_) => {
                eprintln!("usage: ledge-determinism [TICKS]");
                std::process::exit(2);
            }
        },
    };
    let mut world = ledge_shared::scene::warmup_room();
    ledge_shared::scene::run_scripted(&mut world, ticks);
    println!("{:016x}", world.state_hash());
}
