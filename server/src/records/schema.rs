//! The records database's schema, created and migrated by the server at
//! start: a version table and one step per version, in SQL both SQLite and
//! PostgreSQL take. A database from a newer server is refused, not touched.

use sqlx::AnyConnection;
use sqlx::{Connection, Row};

/// The schema version this server writes.
pub const SCHEMA_VERSION: i64 = 1;

/// Each version's statements, in order: `STEPS[i]` goes from version `i`
/// to `i + 1`.
const STEPS: &[&[&str]] = &[&[
    "CREATE TABLE runs (
        run_key TEXT PRIMARY KEY,
        level_hash TEXT NOT NULL,
        level_name TEXT NOT NULL,
        player TEXT NOT NULL,
        ticks BIGINT NOT NULL,
        tick_rate BIGINT NOT NULL,
        millis BIGINT NOT NULL,
        deaths BIGINT NOT NULL,
        coins BIGINT NOT NULL,
        place BIGINT NOT NULL,
        finished_at BIGINT NOT NULL,
        replay_id TEXT
    )",
    "CREATE INDEX runs_by_level_time ON runs (level_hash, millis)",
    "CREATE INDEX runs_by_level_player ON runs (level_hash, player, millis)",
]];

const _: () = assert!(STEPS.len() as i64 == SCHEMA_VERSION);

/// What [`migrate`] found.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Migrated {
    /// The schema is current (`from`: the version it was at).
    Current {
        /// The version before (0: a new database).
        from: i64,
    },
    /// The database is from a newer server: left alone.
    Newer(i64),
}

/// Brings the schema to [`SCHEMA_VERSION`] in one transaction (on
/// PostgreSQL under an advisory lock, so servers starting together
/// migrate one after the other).
pub async fn migrate(conn: &mut AnyConnection) -> Result<Migrated, sqlx::Error> {
    let postgres = conn.backend_name() == "PostgreSQL";
    let mut tx = conn.begin().await?;
    if postgres {
        sqlx::query("SELECT pg_advisory_xact_lock(7465646765)")
            .execute(&mut *tx)
            .await?;
    }
    sqlx::query("CREATE TABLE IF NOT EXISTS ledge_schema (version BIGINT NOT NULL)")
        .execute(&mut *tx)
        .await?;
    let row = sqlx::query("SELECT MAX(version) AS version FROM ledge_schema")
        .fetch_one(&mut *tx)
        .await?;
    let found: Option<i64> = row.try_get("version")?;
    let from = found.unwrap_or(0);
    if from > SCHEMA_VERSION {
        return Ok(Migrated::Newer(from));
    }
    for step in &STEPS[from as usize..] {
        for statement in *step {
            sqlx::query(*statement).execute(&mut *tx).await?;
        }
    }
    if found.is_none() {
        sqlx::query("INSERT INTO ledge_schema (version) VALUES ($1)")
            .bind(SCHEMA_VERSION)
            .execute(&mut *tx)
            .await?;
    } else if from < SCHEMA_VERSION {
        sqlx::query("UPDATE ledge_schema SET version = $1")
            .bind(SCHEMA_VERSION)
            .execute(&mut *tx)
            .await?;
    }
    tx.commit().await?;
    Ok(Migrated::Current { from })
}
