//! The records database: a pool of connections (sqlx's Any driver, SQLite
//! or PostgreSQL by the target), the queries that store runs and read the
//! top times.
//!
//! SQLite runs in WAL mode with `synchronous = FULL`: a committed run is
//! on disk before the player is told. Times compare in milliseconds, so
//! servers at other tick rates share a level's table; players go by name.

use std::collections::BTreeMap;
use std::time::Duration;

use ledge_shared::protocol::{Standing, TopRun, MAX_TOP};
use sqlx::any::{AnyConnectOptions, AnyPoolOptions};
use sqlx::{Any, Row, Transaction};
use sqlx::{AnyConnection, AnyPool, Connection};

use super::schema::{self, Migrated, SCHEMA_VERSION};
use super::{FinishedRun, RecordsError, RecordsTarget};

/// How long opening the database at start may take.
pub const CONNECT_TIMEOUT: Duration = Duration::from_secs(10);
/// How long a query waits for a connection: a pooled one, or a new one.
/// A refused connection is retried until then (sqlx takes it for a
/// database starting up), so while the database is down each of the
/// writer's tries, and each records page, fails after this long.
pub const ACQUIRE_TIMEOUT: Duration = Duration::from_secs(2);
/// Connections in the pool.
const POOL_SIZE: u32 = 4;
/// Most top entries one query returns.
pub const MAX_TOP_QUERY: u32 = 100;

/// One player's best on a level.
#[derive(Debug, Clone, PartialEq, Eq, serde::Serialize)]
pub struct TopEntry {
    /// 1: the fastest.
    pub place: u32,
    /// The player's name.
    pub player: String,
    /// Its best time, milliseconds.
    pub millis: u64,
    /// That run's ticks and tick rate.
    pub ticks: u64,
    /// Ticks a second of that run.
    pub tick_rate: u64,
    /// Its deaths and coins.
    pub deaths: u64,
    /// Coins of that run.
    pub coins: u64,
    /// When that run finished, milliseconds since the Unix epoch.
    pub finished_at_ms: i64,
    /// The player's finished runs on the level.
    pub runs: u64,
    /// The id of that run's replay (`/replays/ID`), if saved.
    pub replay: Option<String>,
}

/// A level with records.
#[derive(Debug, Clone, PartialEq, Eq, serde::Serialize)]
pub struct LevelSummary {
    /// Its content hash (hex).
    pub hash: String,
    /// Its name (the latest run's).
    pub name: String,
    /// Finished runs.
    pub runs: u64,
    /// Players who finished.
    pub players: u64,
    /// The record, milliseconds.
    pub best_millis: u64,
}

/// The records database.
#[derive(Debug, Clone)]
pub struct RecordStore {
    pool: AnyPool,
    target: String,
}

/// The Any driver's URL of an SQLite file (created if missing).
fn sqlite_url(path: &std::path::Path) -> Result<String, String> {
    let text = path
        .to_str()
        .ok_or_else(|| format!("{}: not UTF-8", path.display()))?;
    let escaped = text
        .replace('%', "%25")
        .replace('?', "%3F")
        .replace('#', "%23");
    Ok(format!("sqlite://{escaped}?mode=rwc"))
}

impl RecordStore {
    /// Opens (creating and migrating) the records at `target`; `None` when
    /// it is [`RecordsTarget::Off`].
    pub async fn open(target: &RecordsTarget) -> Result<Option<RecordStore>, RecordsError> {
        let described = target.describe();
        let open_err = |source| RecordsError::Open {
            target: described.clone(),
            source,
        };
        let url = match target {
            RecordsTarget::Off => return Ok(None),
            RecordsTarget::Sqlite(path) => {
                if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
                    std::fs::create_dir_all(dir).map_err(|e| open_err(sqlx::Error::Io(e)))?;
                }
                sqlite_url(path).map_err(|e| open_err(sqlx::Error::Configuration(e.into())))?
            }
            RecordsTarget::Url(url) => url.clone(),
        };
        sqlx::any::install_default_drivers();
        let options: AnyConnectOptions = url.parse().map_err(open_err)?;
        // One connection first: a bad file or an unreachable server fails
        // at once (the pool would retry until its timeout).
        let mut conn = tokio::time::timeout(CONNECT_TIMEOUT, AnyConnection::connect_with(&options))
            .await
            .map_err(|_| open_err(sqlx::Error::PoolTimedOut))?
            .map_err(open_err)?;
        set_up(&mut conn).await.map_err(open_err)?;
        let migrated = schema::migrate(&mut conn).await.map_err(open_err)?;
        let _ = conn.close().await;
        match migrated {
            Migrated::Current { from } => {
                if from != SCHEMA_VERSION {
                    tracing::info!(records = %described, from, to = SCHEMA_VERSION, "records schema made");
                }
            }
            Migrated::Newer(found) => {
                return Err(RecordsError::NewerSchema {
                    target: described,
                    found,
                    known: SCHEMA_VERSION,
                })
            }
        }
        let pool = AnyPoolOptions::new()
            .max_connections(POOL_SIZE)
            .acquire_timeout(ACQUIRE_TIMEOUT)
            .after_connect(|conn, _| Box::pin(set_up(conn)))
            .connect_lazy_with(options);
        Ok(Some(RecordStore {
            pool,
            target: described,
        }))
    }

    /// The file or URL (without a password), for messages.
    pub fn target(&self) -> &str {
        &self.target
    }

    fn query_err(&self) -> impl Fn(sqlx::Error) -> RecordsError + '_ {
        |source| RecordsError::Query {
            target: self.target.clone(),
            source,
        }
    }

    /// Stores `runs` in one transaction and says where each stands (a run
    /// stored before, by its key, is not stored again and stands as it
    /// did). Nothing is stored unless everything is. Each level's players'
    /// bests are read once per batch and kept up to date in memory, so a
    /// batch costs its inserts and one query per level.
    pub async fn store(&self, runs: &[FinishedRun]) -> Result<Vec<Standing>, RecordsError> {
        let err = self.query_err();
        let mut conn = self.pool.acquire().await.map_err(&err)?;
        let mut tx = conn.begin().await.map_err(&err)?;
        let mut bests: BTreeMap<&str, Bests> = BTreeMap::new();
        for run in runs {
            if !bests.contains_key(run.level_hash.as_str()) {
                let level = Bests::read(&mut tx, &run.level_hash).await.map_err(&err)?;
                bests.insert(&run.level_hash, level);
            }
        }
        let mut news = Vec::with_capacity(runs.len());
        for run in runs {
            let inserted = insert(&mut tx, run).await.map_err(&err)?;
            let level = bests.get_mut(run.level_hash.as_str()).expect("read above");
            news.push(level.add(run, inserted));
        }
        tx.commit().await.map_err(&err)?;
        let ranked: BTreeMap<&str, Vec<(u64, &str)>> =
            bests.iter().map(|(&h, b)| (h, b.ranked())).collect();
        Ok(runs
            .iter()
            .zip(news)
            .map(|(run, (new_personal_best, new_record))| {
                let level = &bests[run.level_hash.as_str()];
                let ranked = &ranked[run.level_hash.as_str()];
                let personal_best = level.of(&run.player).unwrap_or(run.millis());
                Standing {
                    millis: run.millis(),
                    personal_best,
                    new_personal_best,
                    new_record,
                    rank: ranked.partition_point(|&(b, _)| b < personal_best) as u32 + 1,
                    top: ranked
                        .iter()
                        .take(MAX_TOP)
                        .map(|&(millis, name)| TopRun {
                            name: name.to_owned(),
                            millis,
                        })
                        .collect(),
                }
            })
            .collect())
    }

    /// The level's best `n` players (at most [`MAX_TOP_QUERY`]), fastest
    /// first.
    pub async fn top(&self, level_hash: &str, n: u32) -> Result<Vec<TopEntry>, RecordsError> {
        let rows = sqlx::query(
            "SELECT r.player, r.millis, r.ticks, r.tick_rate, r.deaths, r.coins, r.finished_at, \
                    r.replay_id, b.runs \
             FROM runs r \
             JOIN (SELECT player, MIN(millis) AS best, COUNT(*) AS runs FROM runs \
                   WHERE level_hash = $1 GROUP BY player) b \
               ON r.player = b.player AND r.millis = b.best \
             WHERE r.level_hash = $1 \
             ORDER BY r.millis ASC, r.finished_at ASC, r.player ASC",
        )
        .bind(level_hash)
        .fetch_all(&self.pool)
        .await
        .map_err(self.query_err())?;
        let mut out: Vec<TopEntry> = Vec::new();
        for row in rows {
            let player: String = row.try_get("player").map_err(self.query_err())?;
            // A player's best may be tied by its own runs: the first one.
            if out.iter().any(|e| e.player == player) {
                continue;
            }
            if out.len() as u32 >= n.min(MAX_TOP_QUERY) {
                break;
            }
            let get = |c: &str| row.try_get::<i64, _>(c).map(|v| v.max(0) as u64);
            let entry = (|| {
                Ok::<_, sqlx::Error>(TopEntry {
                    place: out.len() as u32 + 1,
                    player: player.clone(),
                    millis: get("millis")?,
                    ticks: get("ticks")?,
                    tick_rate: get("tick_rate")?,
                    deaths: get("deaths")?,
                    coins: get("coins")?,
                    finished_at_ms: row.try_get("finished_at")?,
                    runs: get("runs")?,
                    replay: row.try_get("replay_id")?,
                })
            })()
            .map_err(self.query_err())?;
            out.push(entry);
        }
        Ok(out)
    }

    /// Every level with records, by name.
    pub async fn levels(&self) -> Result<Vec<LevelSummary>, RecordsError> {
        let rows = sqlx::query(
            "SELECT level_hash, MAX(level_name) AS name, COUNT(*) AS runs, \
                    COUNT(DISTINCT player) AS players, MIN(millis) AS best \
             FROM runs GROUP BY level_hash ORDER BY MAX(level_name), level_hash",
        )
        .fetch_all(&self.pool)
        .await
        .map_err(self.query_err())?;
        rows.iter()
            .map(|row| {
                let get = |c: &str| row.try_get::<i64, _>(c).map(|v| v.max(0) as u64);
                Ok(LevelSummary {
                    hash: row.try_get("level_hash")?,
                    name: row.try_get("name")?,
                    runs: get("runs")?,
                    players: get("players")?,
                    best_millis: get("best")?,
                })
            })
            .collect::<Result<_, sqlx::Error>>()
            .map_err(self.query_err())
    }

    /// `player`'s best run on the level: its time (milliseconds) and its
    /// replay's id, if it has one.
    pub async fn best_of(
        &self,
        level_hash: &str,
        player: &str,
    ) -> Result<Option<(u64, Option<String>)>, RecordsError> {
        let row = sqlx::query(
            "SELECT millis, replay_id FROM runs WHERE level_hash = $1 AND player = $2 \
             ORDER BY millis ASC, finished_at ASC LIMIT 1",
        )
        .bind(level_hash)
        .bind(player)
        .fetch_optional(&self.pool)
        .await
        .map_err(self.query_err())?;
        let Some(row) = row else {
            return Ok(None);
        };
        let millis: i64 = row.try_get("millis").map_err(self.query_err())?;
        let replay: Option<String> = row.try_get("replay_id").map_err(self.query_err())?;
        Ok(Some((millis.max(0) as u64, replay)))
    }

    /// Runs stored under `key` (0 or 1: for the tests).
    pub async fn count_key(&self, key: &str) -> Result<u64, RecordsError> {
        let row = sqlx::query("SELECT COUNT(*) AS n FROM runs WHERE run_key = $1")
            .bind(key)
            .fetch_one(&self.pool)
            .await
            .map_err(self.query_err())?;
        let n: i64 = row.try_get("n").map_err(self.query_err())?;
        Ok(n.max(0) as u64)
    }

    /// Closes the pool (waits for connections to return).
    pub async fn close(&self) {
        self.pool.close().await;
    }
}

/// Sets a new connection up: on SQLite, the write-ahead log and a sync at
/// every commit (a stored run survives a crash), and a wait for the lock.
async fn set_up(conn: &mut AnyConnection) -> Result<(), sqlx::Error> {
    if conn.backend_name() == "SQLite" {
        for pragma in [
            "PRAGMA journal_mode = WAL",
            "PRAGMA synchronous = FULL",
            "PRAGMA busy_timeout = 5000",
        ] {
            sqlx::query(pragma).execute(&mut *conn).await?;
        }
    }
    Ok(())
}

/// Every player's best time on one level, in milliseconds.
#[derive(Debug, Default)]
struct Bests(BTreeMap<String, u64>);

impl Bests {
    /// The level's bests as stored.
    async fn read(tx: &mut Transaction<'_, Any>, level_hash: &str) -> Result<Bests, sqlx::Error> {
        let rows = sqlx::query(
            "SELECT player, MIN(millis) AS best FROM runs WHERE level_hash = $1 GROUP BY player",
        )
        .bind(level_hash.to_owned())
        .fetch_all(&mut **tx)
        .await?;
        let mut bests = Bests::default();
        for row in rows {
            let best: i64 = row.try_get("best")?;
            bests.0.insert(row.try_get("player")?, best.max(0) as u64);
        }
        Ok(bests)
    }

    /// `player`'s best.
    fn of(&self, player: &str) -> Option<u64> {
        self.0.get(player).copied()
    }

    /// Counts `run` (if it was `inserted`): whether it beat its player's
    /// best and the level's record.
    fn add(&mut self, run: &FinishedRun, inserted: bool) -> (bool, bool) {
        let millis = run.millis();
        let record = self.0.values().min().copied();
        let own = self.of(&run.player);
        if !inserted {
            return (false, false);
        }
        self.0
            .insert(run.player.clone(), own.map_or(millis, |b| b.min(millis)));
        (
            own.is_none_or(|b| millis < b),
            record.is_none_or(|b| millis < b),
        )
    }

    /// (best, player), fastest first (then by name).
    fn ranked(&self) -> Vec<(u64, &str)> {
        let mut v: Vec<(u64, &str)> = self.0.iter().map(|(p, &b)| (b, p.as_str())).collect();
        v.sort();
        v
    }
}

/// Inserts `run` unless its key is stored; whether it was.
async fn insert(tx: &mut Transaction<'_, Any>, run: &FinishedRun) -> Result<bool, sqlx::Error> {
    let inserted = sqlx::query(
        "INSERT INTO runs (run_key, level_hash, level_name, player, ticks, tick_rate, millis, \
                           deaths, coins, place, finished_at, replay_id) \
         VALUES ($1, $2, $3, $4, $5, $6, $7, $8, $9, $10, $11, $12) \
         ON CONFLICT (run_key) DO NOTHING",
    )
    .bind(run.key.clone())
    .bind(run.level_hash.clone())
    .bind(run.level_name.clone())
    .bind(run.player.clone())
    .bind(i64::from(run.ticks))
    .bind(i64::from(run.tick_rate))
    .bind(run.millis() as i64)
    .bind(i64::from(run.deaths))
    .bind(i64::from(run.coins))
    .bind(i64::from(run.place))
    .bind(run.finished_at_ms)
    .bind(run.replay_id.clone())
    .execute(&mut **tx)
    .await?
    .rows_affected();
    Ok(inserted == 1)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn run(key: &str, player: &str, ticks: u32) -> FinishedRun {
        FinishedRun {
            key: key.into(),
            level_hash: "aa".repeat(32),
            level_name: "default".into(),
            player: player.into(),
            ticks,
            tick_rate: 60,
            deaths: 1,
            coins: 2,
            place: 1,
            finished_at_ms: 1_700_000_000_000,
            replay_id: Some(format!("replay-of-{key}")),
        }
    }

    async fn open(dir: &tempfile::TempDir) -> RecordStore {
        let target = RecordsTarget::Sqlite(dir.path().join("sub/records.sqlite"));
        RecordStore::open(&target).await.unwrap().expect("on")
    }

    #[tokio::test]
    async fn runs_are_stored_once_ranked_and_a_slower_run_keeps_the_best() {
        let dir = tempfile::tempdir().unwrap();
        let store = open(&dir).await;
        let s = store.store(&[run("a1", "ann", 600)]).await.unwrap();
        assert!(s[0].new_record && s[0].new_personal_best);
        assert_eq!(
            (s[0].millis, s[0].personal_best, s[0].rank),
            (10_000, 10_000, 1)
        );
        // Two in one batch: bob is faster (a record), ann slower (no best).
        let s = store
            .store(&[run("b1", "bob", 540), run("a2", "ann", 660)])
            .await
            .unwrap();
        assert!(s[0].new_record && s[0].new_personal_best && s[0].rank == 1);
        assert!(!s[1].new_record && !s[1].new_personal_best);
        assert_eq!((s[1].personal_best, s[1].rank), (10_000, 2));
        let names: Vec<&str> = s[1].top.iter().map(|t| t.name.as_str()).collect();
        assert_eq!(names, ["bob", "ann"]);
        // The same finish again (a retry after a lost commit): stored once.
        let again = store.store(&[run("b1", "bob", 540)]).await.unwrap();
        assert!(!again[0].new_record && !again[0].new_personal_best);
        assert_eq!(store.count_key("b1").await.unwrap(), 1);
        let top = store.top(&"aa".repeat(32), 10).await.unwrap();
        assert_eq!(top.len(), 2);
        assert_eq!(
            (top[0].player.as_str(), top[0].millis, top[0].runs),
            ("bob", 9_000, 1)
        );
        assert_eq!(
            (top[1].player.as_str(), top[1].millis, top[1].runs),
            ("ann", 10_000, 2)
        );
        // Each best with its own run's replay.
        assert_eq!(top[0].replay.as_deref(), Some("replay-of-b1"));
        assert_eq!(top[1].replay.as_deref(), Some("replay-of-a1"));
        let level = "aa".repeat(32);
        assert_eq!(
            store.best_of(&level, "ann").await.unwrap(),
            Some((10_000, Some("replay-of-a1".into())))
        );
        assert_eq!(store.best_of(&level, "zed").await.unwrap(), None);
        assert_eq!(store.top(&"aa".repeat(32), 1).await.unwrap().len(), 1);
        let levels = store.levels().await.unwrap();
        assert_eq!(levels.len(), 1);
        assert_eq!(
            (levels[0].runs, levels[0].players, levels[0].best_millis),
            (3, 2, 9_000)
        );
        store.close().await;
        // Reopened: everything is still there.
        let store = open(&dir).await;
        assert_eq!(store.top(&"aa".repeat(32), 10).await.unwrap(), top);
        store.close().await;
    }

    #[tokio::test]
    async fn a_newer_or_broken_database_is_refused_saying_what_to_do() {
        let dir = tempfile::tempdir().unwrap();
        let store = open(&dir).await;
        sqlx::query("UPDATE ledge_schema SET version = 99")
            .execute(&store.pool)
            .await
            .unwrap();
        store.close().await;
        let target = RecordsTarget::Sqlite(dir.path().join("sub/records.sqlite"));
        let e = RecordStore::open(&target).await.unwrap_err();
        assert!(
            matches!(e, RecordsError::NewerSchema { found: 99, .. }),
            "{e}"
        );
        assert!(e.to_string().contains("newer ledge-server"), "{e}");
        // Not a database at all.
        let junk = dir.path().join("junk.sqlite");
        std::fs::write(&junk, vec![0x55; 8192]).unwrap();
        let e = RecordStore::open(&RecordsTarget::Sqlite(junk))
            .await
            .unwrap_err();
        let text = e.to_string();
        assert!(
            text.contains("junk.sqlite") && text.contains("--records"),
            "{text}"
        );
        // Off is off.
        assert!(RecordStore::open(&RecordsTarget::Off)
            .await
            .unwrap()
            .is_none());
    }
}
