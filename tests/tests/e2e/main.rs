//! End-to-end tests: the real server in-process, headless clients (and
//! Chromium, the real client window) over real QUIC, WebTransport and
//! WebSocket on loopback. One binary, one link step; every file a module.
//! `cargo nextest` runs each test in a process of its own (the test
//! groups and weights are in `.config/nextest.toml`).

mod admission;
mod agones;
mod background;
mod bots;
mod browser_client;
mod browser_harness;
mod browser_replay;
mod churn;
mod conditioned;
mod deploy_manifests;
mod gameplay;
mod ghosts;
mod handshake;
mod impaired;
mod level_download;
mod matches;
mod metrics;
mod names;
mod page_session_quic;
mod prediction;
mod prediction_crowd;
mod records;
mod records_kill;
mod records_postgres;
mod remote_players;
mod replays;
mod resume;
mod robustness;
mod rooms_by_name;
mod roster;
mod rotation;
mod seats;
mod spectators;
mod stall;
mod trust;
mod web_hostile;
mod web_transports;
mod wire_budget;
