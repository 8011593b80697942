//! `ledge-netsim`: a link conditioner. The kernel of the machines ledge is
//! tested on has no `netem`, so impairment is simulated in user space: a
//! UDP relay between clients and the server that delays, jitters, loses
//! (randomly or in bursts), duplicates and reorders datagrams, each
//! direction on its own terms.
//!
//! * [`config`]: what a direction does ([`LinkConfig`]);
//! * [`loss`]: random (Bernoulli) and burst (Gilbert-Elliott) loss
//!   ([`Loss`]);
//! * [`link`]: the sans-IO model of one direction ([`Link`]): pure state,
//!   time passed in, seeded, so tests of the model are exact and fast;
//! * [`relay`]: the tokio UDP relay applying it ([`Relay`]), with live
//!   control (configurations, blackouts) and counters;
//! * [`counters`]: the relay's figures ([`RelayStats`]);
//! * [`error`]: what can fail.
//!
//! The `ledge-netsim` binary runs a relay from the command line.
#![deny(missing_docs)]

pub mod config;
pub mod counters;
pub mod error;
mod flow;
pub mod link;
pub mod loss;
pub mod relay;

pub use config::LinkConfig;
pub use counters::{Direction, DirectionStats, RelayStats};
pub use error::{ConfigError, RelayError};
pub use link::{Link, LinkStats, Verdict};
pub use loss::Loss;
pub use relay::{Relay, RelayConfig};
