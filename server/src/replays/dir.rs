//! The replays folder: `ID.ledgereplay` files, oldest first, within a size
//! cap. Saving writes `ID.tmp` and renames it, so a reader (the web port)
//! never sees half a file; past the cap the oldest files go, except those
//! the caller keeps (the replays of records).

use std::collections::{BTreeSet, VecDeque};
use std::io;
use std::path::{Path, PathBuf};
use std::time::SystemTime;

use super::{is_replay_id, EXTENSION};

/// The folder and what is in it (see the module documentation).
#[derive(Debug)]
pub struct ReplayDir {
    dir: PathBuf,
    cap: u64,
    /// Every replay, oldest first, with its size.
    files: VecDeque<(String, u64)>,
    total: u64,
}

/// What [`ReplayDir::prune`] deleted.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Pruned {
    /// Files deleted.
    pub files: u64,
    /// Their bytes.
    pub bytes: u64,
}

impl ReplayDir {
    /// Opens `dir` (created if missing), keeping at most `cap` bytes:
    /// lists its replays by age and deletes leftover `.tmp` files.
    pub fn open(dir: &Path, cap: u64) -> io::Result<ReplayDir> {
        std::fs::create_dir_all(dir)?;
        let mut found: Vec<(SystemTime, String, u64)> = Vec::new();
        for entry in std::fs::read_dir(dir)? {
            let entry = entry?;
            let path = entry.path();
            let Some(name) = path.file_name().and_then(|n| n.to_str()) else {
                continue;
            };
            if let Some(id) = name.strip_suffix(".tmp").filter(|id| is_replay_id(id)) {
                let _ = std::fs::remove_file(&path);
                tracing::debug!(id, "deleted a replay left half-written");
                continue;
            }
            let Some(id) = name
                .strip_suffix(EXTENSION)
                .and_then(|n| n.strip_suffix('.'))
                .filter(|id| is_replay_id(id))
            else {
                continue;
            };
            let meta = entry.metadata()?;
            let modified = meta.modified().unwrap_or(SystemTime::UNIX_EPOCH);
            found.push((modified, id.to_owned(), meta.len()));
        }
        found.sort();
        let total = found.iter().map(|f| f.2).sum();
        Ok(ReplayDir {
            dir: dir.to_owned(),
            cap,
            files: found.into_iter().map(|(_, id, len)| (id, len)).collect(),
            total,
        })
    }

    /// The folder.
    pub fn dir(&self) -> &Path {
        &self.dir
    }

    /// The path of replay `id` (which may not exist).
    pub fn path_of(dir: &Path, id: &str) -> PathBuf {
        dir.join(format!("{id}.{EXTENSION}"))
    }

    /// Bytes of all replays.
    pub fn total(&self) -> u64 {
        self.total
    }

    /// Replays kept.
    pub fn len(&self) -> usize {
        self.files.len()
    }

    /// Whether there is none.
    pub fn is_empty(&self) -> bool {
        self.files.is_empty()
    }

    /// Whether the replays take more than the cap.
    pub fn over_cap(&self) -> bool {
        self.total > self.cap
    }

    /// Saves `bytes` as replay `id` (replacing one of that id), newest.
    pub fn save(&mut self, id: &str, bytes: &[u8]) -> io::Result<()> {
        if !is_replay_id(id) {
            return Err(io::Error::new(
                io::ErrorKind::InvalidInput,
                format!("{id:?} is not a replay id"),
            ));
        }
        let tmp = self.dir.join(format!("{id}.tmp"));
        std::fs::write(&tmp, bytes)?;
        if let Err(e) = std::fs::rename(&tmp, Self::path_of(&self.dir, id)) {
            let _ = std::fs::remove_file(&tmp);
            return Err(e);
        }
        if let Some(i) = self.files.iter().position(|(f, _)| f == id) {
            let (_, len) = self.files.remove(i).expect("found");
            self.total -= len;
        }
        self.files.push_back((id.to_owned(), bytes.len() as u64));
        self.total += bytes.len() as u64;
        Ok(())
    }

    /// Deletes the oldest replays not in `keep` until the rest fit the
    /// cap (the kept ones alone may not). The newest is never deleted: a
    /// run's replay is saved just before its run is stored in the records,
    /// so `keep` cannot name it yet.
    pub fn prune(&mut self, keep: &BTreeSet<String>) -> io::Result<Pruned> {
        let mut pruned = Pruned::default();
        let mut i = 0;
        while self.total > self.cap && i + 1 < self.files.len() {
            if keep.contains(&self.files[i].0) {
                i += 1;
                continue;
            }
            let (id, len) = self.files.remove(i).expect("in range");
            match std::fs::remove_file(Self::path_of(&self.dir, &id)) {
                Ok(()) => {}
                Err(e) if e.kind() == io::ErrorKind::NotFound => {}
                Err(e) => {
                    self.files.insert(i, (id, len));
                    return Err(e);
                }
            }
            self.total -= len;
            pruned.files += 1;
            pruned.bytes += len;
        }
        Ok(pruned)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::replays::replay_id;

    fn ids(n: usize) -> Vec<String> {
        (0..n).map(|i| replay_id(&i.to_string())).collect()
    }

    #[test]
    fn past_the_cap_the_oldest_go_except_those_kept() {
        let tmp = tempfile::tempdir().unwrap();
        let mut dir = ReplayDir::open(tmp.path(), 350).unwrap();
        let ids = ids(5);
        for id in &ids {
            dir.save(id, &[7; 100]).unwrap();
        }
        assert_eq!((dir.len(), dir.total()), (5, 500));
        assert!(dir.over_cap());
        // The oldest is a record's: kept; the next two go.
        let keep = BTreeSet::from([ids[0].clone()]);
        let pruned = dir.prune(&keep).unwrap();
        assert_eq!(
            pruned,
            Pruned {
                files: 2,
                bytes: 200
            }
        );
        let left: Vec<bool> = ids
            .iter()
            .map(|id| ReplayDir::path_of(tmp.path(), id).exists())
            .collect();
        assert_eq!(left, [true, false, false, true, true]);
        assert!(!dir.over_cap());
        // Reopened: the same files, in the same order (by modification
        // time, which the file system keeps coarsely: set apart here).
        for (k, id) in ids.iter().enumerate() {
            if let Ok(f) = std::fs::File::options()
                .append(true)
                .open(ReplayDir::path_of(tmp.path(), id))
            {
                let at = SystemTime::UNIX_EPOCH + std::time::Duration::from_secs(1_000 + k as u64);
                f.set_modified(at).unwrap();
            }
        }
        std::fs::write(tmp.path().join(format!("{}.tmp", ids[1])), b"half").unwrap();
        std::fs::write(tmp.path().join("notes.txt"), b"not a replay").unwrap();
        let mut again = ReplayDir::open(tmp.path(), 150).unwrap();
        assert_eq!((again.len(), again.total()), (3, 300));
        assert!(!tmp.path().join(format!("{}.tmp", ids[1])).exists());
        assert!(tmp.path().join("notes.txt").exists());
        // The newest stays, even alone over the cap.
        again.prune(&BTreeSet::new()).unwrap();
        assert_eq!((again.len(), again.total()), (1, 100));
        assert!(ReplayDir::path_of(tmp.path(), &ids[4]).exists());
    }

    #[test]
    fn saving_an_id_again_replaces_it_and_bad_ids_are_refused() {
        let tmp = tempfile::tempdir().unwrap();
        let mut dir = ReplayDir::open(tmp.path(), 1000).unwrap();
        let id = replay_id("x");
        dir.save(&id, &[1; 10]).unwrap();
        dir.save(&id, &[2; 30]).unwrap();
        assert_eq!((dir.len(), dir.total()), (1, 30));
        assert_eq!(
            std::fs::read(ReplayDir::path_of(tmp.path(), &id)).unwrap(),
            [2; 30]
        );
        assert!(dir.save("../escape", b"x").is_err());
    }
}
