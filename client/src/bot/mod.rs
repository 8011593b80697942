//! Headless bots: brains that play the game through the client library.

pub mod brain;
pub mod misbehave;
pub mod run;
pub mod runner;
pub mod thin;

pub use brain::{Brain, Idle, RandomWalker, SplitMix64};
pub use misbehave::{misbehave, MisbehaveReport, Misbehavior, Outcome};
pub use run::{connect_and_run, run_bot, BotOptions, BotReport, LevelPlayed};
pub use runner::{Runner, RunnerProgress};
pub use thin::{run_thin, run_thin_with, THIN};
