//! Where a replay comes from: a file, or a server's web port
//! (`http://HOST:PORT/replays/ID`, ID 16 hex digits); read whole, never
//! more than a replay file can be ([`MAX_FILE_BYTES`]), the bound checked
//! before anything is allocated.

use std::io::Read;
use std::path::PathBuf;

use anyhow::{bail, Context};
use ledge_shared::protocol::LevelOffer;

use crate::replay::http;
use crate::replay::open::{is_id, MAX_FILE_BYTES};

/// How a replay's URL looks, for messages.
pub const URL_FORM: &str = "http://HOST:PORT/replays/ID (ID: 16 hex digits)";

/// A replay on a server's web port.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ReplayUrl {
    /// `HOST:PORT` (or `HOST`: port 80), as given.
    pub authority: String,
    /// The replay's id, as given.
    pub id: String,
}

impl ReplayUrl {
    /// Reads `http://HOST:PORT/replays/ID`; says what is wrong otherwise.
    pub fn parse(url: &str) -> anyhow::Result<ReplayUrl> {
        let lower = url.to_ascii_lowercase();
        if lower.starts_with("https://") {
            bail!(
                "{url}: a ledge server's web port speaks plain HTTP: give the replay as {URL_FORM}"
            );
        }
        let Some(rest) = lower
            .starts_with("http://")
            .then(|| &url["http://".len()..])
        else {
            bail!("{url}: not a replay URL: give it as {URL_FORM}");
        };
        let (authority, path) = rest.split_once('/').unwrap_or((rest, ""));
        if authority.is_empty() || authority.contains('@') {
            bail!("{url}: no server in it: give the replay as {URL_FORM}");
        }
        let id = path.strip_prefix("replays/").unwrap_or_default();
        if !is_id(id) {
            bail!(
                "{url}: not a replay's address on a ledge server: give it as {URL_FORM}, as the \
                 server's records page links it"
            );
        }
        Ok(ReplayUrl {
            authority: authority.to_owned(),
            id: id.to_owned(),
        })
    }

    /// The replay's URL.
    pub fn url(&self) -> String {
        format!("http://{}/replays/{}", self.authority, self.id)
    }

    /// The URL of the level bundle `offer` on the same server.
    pub fn level_url(&self, offer: &LevelOffer) -> String {
        format!("http://{}/levels/{}", self.authority, offer.hex())
    }
}

/// Where a replay comes from.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Source {
    /// A file.
    File(PathBuf),
    /// A server's web port.
    Url(ReplayUrl),
}

impl Source {
    /// `--replay`'s argument: a URL when it starts with `http://` or
    /// `https://`, else a file.
    pub fn parse(arg: &str) -> anyhow::Result<Source> {
        let lower = arg.to_ascii_lowercase();
        if lower.starts_with("http://") || lower.starts_with("https://") {
            Ok(Source::Url(ReplayUrl::parse(arg)?))
        } else {
            Ok(Source::File(PathBuf::from(arg)))
        }
    }

    /// The server it comes from, for a URL.
    pub fn server(&self) -> Option<&ReplayUrl> {
        match self {
            Source::Url(url) => Some(url),
            Source::File(_) => None,
        }
    }

    /// The file's path or the URL, for messages.
    pub fn describe(&self) -> String {
        match self {
            Source::File(path) => path.display().to_string(),
            Source::Url(url) => url.url(),
        }
    }

    /// The replay's bytes, at most [`MAX_FILE_BYTES`].
    pub fn read(&self) -> anyhow::Result<Vec<u8>> {
        match self {
            Source::File(path) => read_file(path),
            Source::Url(url) => http::get(
                &url.url(),
                MAX_FILE_BYTES,
                "replay",
                "check its ID, or ask the server's operator whether it still keeps it",
            ),
        }
    }
}

/// A replay file's bytes: refused before reading when it is larger than
/// any replay.
fn read_file(path: &std::path::Path) -> anyhow::Result<Vec<u8>> {
    let shown = path.display();
    let file = std::fs::File::open(path)
        .with_context(|| format!("cannot open the replay {shown}: check the path"))?;
    let len = file
        .metadata()
        .with_context(|| format!("cannot read the replay {shown}"))?
        .len();
    if len > MAX_FILE_BYTES {
        bail!(
            "{shown} is {len} bytes, more than a ledge replay can be ({MAX_FILE_BYTES} bytes): \
             it is not a replay"
        );
    }
    let mut bytes = Vec::with_capacity(len as usize);
    file.take(MAX_FILE_BYTES + 1)
        .read_to_end(&mut bytes)
        .with_context(|| format!("cannot read the replay {shown}"))?;
    if bytes.len() as u64 > MAX_FILE_BYTES {
        bail!("{shown} grew past {MAX_FILE_BYTES} bytes while it was read: it is not a replay");
    }
    Ok(bytes)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_replay_url_names_a_server_and_a_16_digit_id() {
        let url = ReplayUrl::parse("http://192.168.1.20:8080/replays/00ff00ff00ff00fA").unwrap();
        assert_eq!(url.authority, "192.168.1.20:8080");
        assert_eq!(url.id, "00ff00ff00ff00fA");
        assert_eq!(
            url.url(),
            "http://192.168.1.20:8080/replays/00ff00ff00ff00fA"
        );
        let offer = LevelOffer {
            sha256: [0xab; 32],
            size: 1,
        };
        assert_eq!(
            url.level_url(&offer),
            format!("http://192.168.1.20:8080/levels/{}", "ab".repeat(32))
        );
        assert!(matches!(
            Source::parse("HTTP://[::1]:80/replays/0123456789abcdef").unwrap(),
            Source::Url(ReplayUrl { authority, .. }) if authority == "[::1]:80"
        ));
        assert_eq!(
            Source::parse("runs/ada.ledgereplay").unwrap(),
            Source::File(PathBuf::from("runs/ada.ledgereplay"))
        );
        for bad in [
            "https://host:8080/replays/0123456789abcdef",
            "http://host:8080/replays/0123456789abcde",
            "http://host:8080/replays/0123456789abcdeg",
            "http://host:8080/records",
            "http:///replays/0123456789abcdef",
            "http://user@host/replays/0123456789abcdef",
            "http://host:8080/replays/0123456789abcdef?x=1",
        ] {
            let err = Source::parse(bad).unwrap_err().to_string();
            assert!(err.contains("http://HOST:PORT/replays/ID"), "{bad}: {err}");
        }
    }

    #[test]
    fn a_file_larger_than_any_replay_is_refused_before_it_is_read() {
        let tmp = tempfile::tempdir().unwrap();
        let dir = tmp.path();
        let path = dir.join("huge.bin");
        let file = std::fs::File::create(&path).unwrap();
        file.set_len(MAX_FILE_BYTES + 1).unwrap();
        let err = format!("{:#}", read_file(&path).unwrap_err());
        assert!(err.contains(&MAX_FILE_BYTES.to_string()), "{err}");
        let missing = format!("{:#}", read_file(&dir.join("missing")).unwrap_err());
        assert!(missing.contains("check the path"), "{missing}");
    }
}
