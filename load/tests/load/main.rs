//! ledge-load's integration tests in one binary.

mod server_metrics;
mod thin_load;
