//! The server's records: every finished run, stored once, in SQLite (a file,
//! the default) or PostgreSQL (a fleet sharing one store), through one code
//! path (sqlx's Any driver).
//!
//! A room hands each finished run to the writer ([`writer`]), which stores
//! runs in batches, one transaction each, and only then tells each player
//! where its run stands ([`ledge_shared::protocol::Standing`]): a run the
//! server said was recorded survives the server being killed. A run's key
//! ([`FinishedRun::key`]) is unique to its finish, so storing it twice (a
//! retry after a lost commit) stores it once. The web port shows them
//! ([`crate::web::records_pages`]). A store that cannot be opened, or fails
//! later, never stops play: the server says so and goes on without it.

pub mod schema;
pub mod store;
pub mod writer;

use std::path::{Path, PathBuf};

pub use store::{LevelSummary, RecordStore, TopEntry};
pub use writer::{RecordsHandle, WRITE_QUEUE};

/// Where the records go (`--records`).
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum RecordsTarget {
    /// No records (`--records off`).
    Off,
    /// An SQLite file, created if missing.
    Sqlite(PathBuf),
    /// A database URL (`postgres://...`; `sqlite://...` also works).
    Url(String),
}

/// File name of the default records database, in the certificate
/// directory (the server's own state: the certificate and the records).
pub const DEFAULT_FILE: &str = "records.sqlite";

impl RecordsTarget {
    /// `--records`'s value: `off`, a `postgres://` or `sqlite:` URL, or a
    /// file path.
    pub fn parse(value: &str) -> RecordsTarget {
        let v = value.trim();
        if v.eq_ignore_ascii_case("off") || v.eq_ignore_ascii_case("none") {
            RecordsTarget::Off
        } else if v.starts_with("postgres://")
            || v.starts_with("postgresql://")
            || v.starts_with("sqlite:")
        {
            RecordsTarget::Url(v.to_owned())
        } else {
            RecordsTarget::Sqlite(PathBuf::from(v))
        }
    }

    /// The default: [`DEFAULT_FILE`] in `cert_dir`, beside the
    /// certificate.
    pub fn in_state_dir(cert_dir: &Path) -> RecordsTarget {
        RecordsTarget::Sqlite(cert_dir.join(DEFAULT_FILE))
    }

    /// What to name in messages: the path, or the URL without its
    /// password.
    pub fn describe(&self) -> String {
        match self {
            RecordsTarget::Off => "off".into(),
            RecordsTarget::Sqlite(path) => path.display().to_string(),
            RecordsTarget::Url(url) => without_password(url),
        }
    }
}

/// `url` with any password replaced by `***` (for logs and errors).
pub fn without_password(url: &str) -> String {
    let Some((scheme, rest)) = url.split_once("://") else {
        return url.to_owned();
    };
    let (authority, tail) = rest.split_at(rest.find('/').unwrap_or(rest.len()));
    match authority.rsplit_once('@') {
        Some((user_info, host)) => {
            let user = user_info.split(':').next().unwrap_or("");
            format!("{scheme}://{user}:***@{host}{tail}")
        }
        None => url.to_owned(),
    }
}

/// Why the records failed.
#[derive(Debug, thiserror::Error)]
pub enum RecordsError {
    /// The database could not be opened or reached.
    #[error(
        "cannot open the records database {target}: {source}; fix it or pass --records with \
         another file or URL (or --records off); the server plays on without records meanwhile"
    )]
    Open {
        /// The file or URL (without its password).
        target: String,
        /// Why.
        source: sqlx::Error,
    },
    /// The database was made by a newer server.
    #[error(
        "the records database {target} has schema version {found}, newer than this server's \
         {known}: run a newer ledge-server, or pass --records with another file; the server \
         plays on without records"
    )]
    NewerSchema {
        /// The file or URL.
        target: String,
        /// Its version.
        found: i64,
        /// Ours.
        known: i64,
    },
    /// A query failed.
    #[error("records database {target}: {source}")]
    Query {
        /// The file or URL.
        target: String,
        /// Why.
        source: sqlx::Error,
    },
}

/// Milliseconds since the Unix epoch (0 if the clock is before it).
pub fn unix_millis() -> i64 {
    std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(0, |d| i64::try_from(d.as_millis()).unwrap_or(i64::MAX))
}

/// One finished run, as stored.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct FinishedRun {
    /// Unique to this finish: the server's instance, the room, the
    /// player's id and the tick it finished at.
    pub key: String,
    /// The level's content hash (its bundle's SHA-256, hex).
    pub level_hash: String,
    /// The level's name.
    pub level_name: String,
    /// The player's name (records go by name).
    pub player: String,
    /// The run's ticks.
    pub ticks: u32,
    /// Ticks a second it was run at.
    pub tick_rate: u32,
    /// Deaths during the run.
    pub deaths: u32,
    /// Coins picked up.
    pub coins: u32,
    /// Its finishing place in the room.
    pub place: u32,
    /// When it finished, milliseconds since the Unix epoch.
    pub finished_at_ms: i64,
    /// Its replay's id ([`crate::replays::replay_id`]), if one is saved.
    pub replay_id: Option<String>,
}

impl FinishedRun {
    /// The run's time in milliseconds (what runs at different tick rates
    /// are compared by).
    pub fn millis(&self) -> u64 {
        u64::from(self.ticks) * 1000 / u64::from(self.tick_rate.max(1))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn targets_parse_and_passwords_stay_out_of_messages() {
        assert_eq!(RecordsTarget::parse("off"), RecordsTarget::Off);
        assert_eq!(
            RecordsTarget::parse("runs.db"),
            RecordsTarget::Sqlite("runs.db".into())
        );
        let pg = RecordsTarget::parse("postgres://ledge:secret@db.example/records");
        assert!(matches!(pg, RecordsTarget::Url(_)));
        assert_eq!(pg.describe(), "postgres://ledge:***@db.example/records");
        assert_eq!(
            without_password("postgres://db.example/records"),
            "postgres://db.example/records"
        );
        assert_eq!(
            RecordsTarget::in_state_dir(Path::new("/srv/ledge/certs")),
            RecordsTarget::Sqlite("/srv/ledge/certs/records.sqlite".into())
        );
    }

    #[test]
    fn a_run_is_timed_in_milliseconds_at_its_tick_rate() {
        let run = FinishedRun {
            key: "k".into(),
            level_hash: "h".into(),
            level_name: "n".into(),
            player: "p".into(),
            ticks: 600,
            tick_rate: 60,
            deaths: 0,
            coins: 0,
            place: 1,
            finished_at_ms: 0,
            replay_id: None,
        };
        assert_eq!(run.millis(), 10_000);
        let fast = FinishedRun {
            ticks: 1200,
            tick_rate: 120,
            ..run
        };
        assert_eq!(fast.millis(), 10_000);
    }
}
