//! The web page's files (`--web-root`), read into memory once at start.
//!
//! Only the directory's regular files (no subdirectories), at most
//! [`MAX_FILES`] of them and [`MAX_BYTES`] in all, so serving them never
//! touches the disk and a request can only name a file that was there at
//! start. A missing directory or `index.html` is not an error: the server
//! runs without its page and says what to build ([`WebRoot::missing`]).

use std::collections::BTreeMap;
use std::io::Read;
use std::path::{Path, PathBuf};

use bytes::Bytes;

/// Most files served.
pub const MAX_FILES: usize = 64;
/// Most bytes of files served, in all.
pub const MAX_BYTES: u64 = 64 << 20;

/// What to run to build the page.
pub const BUILD_COMMAND: &str = "scripts/build-web";

/// One file to serve.
#[derive(Debug, Clone)]
pub struct WebFile {
    /// Its bytes.
    pub body: Bytes,
    /// Its `Content-Type`.
    pub content_type: &'static str,
    /// Its entity tag: the SHA-256 of its bytes, quoted, so a browser
    /// reloading the page revalidates it (`If-None-Match`) and gets a 304
    /// instead of the whole file again.
    pub etag: String,
}

/// The quoted entity tag of `bytes`: their SHA-256, lower-case hex
/// (shortened to 128 bits, plenty to tell versions apart).
pub fn etag_of(bytes: &[u8]) -> String {
    let digest = ring::digest::digest(&ring::digest::SHA256, bytes);
    let hex: String = digest.as_ref()[..16]
        .iter()
        .map(|b| format!("{b:02x}"))
        .collect();
    format!("\"{hex}\"")
}

/// Why the web page's directory cannot be served.
#[derive(Debug, thiserror::Error)]
pub enum WebRootError {
    /// More files than [`MAX_FILES`].
    #[error(
        "{dir}: more than {max} files; the web page needs far fewer: point --web-root at the \
         built page (scripts/build-web writes web/dist), not at a directory of other files"
    )]
    TooManyFiles {
        /// The directory.
        dir: PathBuf,
        /// The limit.
        max: usize,
    },
    /// More bytes than [`MAX_BYTES`].
    #[error(
        "{dir}: its files are more than {max_mib} MiB in all, the most the server keeps in \
         memory for the web page: build the page in release mode (scripts/build-web), or \
         remove other files from the directory"
    )]
    TooLarge {
        /// The directory.
        dir: PathBuf,
        /// The limit, MiB.
        max_mib: u64,
    },
    /// A file or the directory could not be read.
    #[error("cannot read {path}: {source}")]
    Read {
        /// What.
        path: PathBuf,
        /// Why.
        source: std::io::Error,
    },
}

/// The page's files, by name.
#[derive(Debug, Default)]
pub struct WebRoot {
    files: BTreeMap<String, WebFile>,
    missing: Option<String>,
}

/// The content type of a file name, by its extension.
pub fn content_type(name: &str) -> &'static str {
    let ext = name.rsplit_once('.').map(|(_, e)| e.to_ascii_lowercase());
    match ext.as_deref() {
        Some("html" | "htm") => "text/html; charset=utf-8",
        Some("js" | "mjs") => "text/javascript; charset=utf-8",
        Some("wasm") => "application/wasm",
        Some("json") => "application/json",
        Some("png") => "image/png",
        Some("css") => "text/css; charset=utf-8",
        Some("txt") => "text/plain; charset=utf-8",
        Some("svg") => "image/svg+xml",
        Some("ico") => "image/x-icon",
        _ => "application/octet-stream",
    }
}

impl WebRoot {
    /// Reads `dir`'s regular files. A missing directory (or `index.html`)
    /// gives a root that says so ([`WebRoot::missing`]); too many or too
    /// large files are an error.
    pub fn load(dir: &Path) -> Result<WebRoot, WebRootError> {
        let read_err = |path: &Path| {
            let path = path.to_owned();
            move |source| WebRootError::Read { path, source }
        };
        let entries = match std::fs::read_dir(dir) {
            Ok(entries) => entries,
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
                return Ok(WebRoot {
                    files: BTreeMap::new(),
                    missing: Some(format!(
                        "the web page is not built: {} does not exist; run {BUILD_COMMAND} \
                         (or point --web-root at the built page)",
                        dir.display()
                    )),
                })
            }
            Err(e) => return Err(read_err(dir)(e)),
        };
        let mut files = BTreeMap::new();
        let mut total = 0u64;
        for entry in entries {
            let entry = entry.map_err(read_err(dir))?;
            let path = entry.path();
            // Follows links: a link to a file is served as the file.
            let meta = std::fs::metadata(&path).map_err(read_err(&path))?;
            let Some(name) = entry.file_name().to_str().map(str::to_owned) else {
                continue;
            };
            if !meta.is_file() || name.starts_with('.') {
                continue;
            }
            if files.len() == MAX_FILES {
                return Err(WebRootError::TooManyFiles {
                    dir: dir.to_owned(),
                    max: MAX_FILES,
                });
            }
            let too_large = || WebRootError::TooLarge {
                dir: dir.to_owned(),
                max_mib: MAX_BYTES >> 20,
            };
            total = total.checked_add(meta.len()).ok_or_else(too_large)?;
            if total > MAX_BYTES {
                return Err(too_large());
            }
            // Bounded again while reading: the file may grow meanwhile.
            let mut body = Vec::with_capacity(meta.len() as usize);
            let file = std::fs::File::open(&path).map_err(read_err(&path))?;
            file.take(meta.len() + 1)
                .read_to_end(&mut body)
                .map_err(read_err(&path))?;
            if body.len() as u64 > meta.len() {
                return Err(WebRootError::Read {
                    path,
                    source: std::io::Error::other("the file grew while being read"),
                });
            }
            let content_type = content_type(&name);
            let etag = etag_of(&body);
            files.insert(
                name,
                WebFile {
                    body: body.into(),
                    content_type,
                    etag,
                },
            );
        }
        let missing = (!files.contains_key("index.html")).then(|| {
            format!(
                "the web page is not built: {} has no index.html; run {BUILD_COMMAND}",
                dir.display()
            )
        });
        Ok(WebRoot { files, missing })
    }

    /// The file called `name`, if it was there at start.
    pub fn get(&self, name: &str) -> Option<&WebFile> {
        self.files.get(name)
    }

    /// Why the page cannot be served (no directory, no `index.html`), if
    /// so: logged at start and answered to `/` with 503.
    pub fn missing(&self) -> Option<&str> {
        self.missing.as_deref()
    }

    /// Number of files.
    pub fn len(&self) -> usize {
        self.files.len()
    }

    /// Whether there are none.
    pub fn is_empty(&self) -> bool {
        self.files.is_empty()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_page_loads_with_its_content_types_and_without_subdirectories() {
        let dir = tempfile::tempdir().unwrap();
        std::fs::write(dir.path().join("index.html"), "<p>hi</p>").unwrap();
        std::fs::write(dir.path().join("game.wasm"), [0, 97, 115, 109]).unwrap();
        std::fs::write(dir.path().join("glue.js"), "x").unwrap();
        std::fs::create_dir(dir.path().join("sub")).unwrap();
        std::fs::write(dir.path().join("sub/secret.txt"), "no").unwrap();
        let root = WebRoot::load(dir.path()).unwrap();
        assert_eq!(root.missing(), None);
        assert_eq!(root.len(), 3);
        assert_eq!(&root.get("index.html").unwrap().body[..], b"<p>hi</p>");
        assert_eq!(
            root.get("game.wasm").unwrap().content_type,
            "application/wasm"
        );
        assert!(root
            .get("glue.js")
            .unwrap()
            .content_type
            .starts_with("text/javascript"));
        assert!(root.get("sub").is_none() && root.get("secret.txt").is_none());
        assert_eq!(content_type("a.PNG"), "image/png");
        assert_eq!(content_type("data.json"), "application/json");
        assert_eq!(content_type("style.css"), "text/css; charset=utf-8");
        assert_eq!(content_type("noext"), "application/octet-stream");
        // Entity tags follow the bytes.
        let (a, b) = (
            root.get("index.html").unwrap(),
            root.get("glue.js").unwrap(),
        );
        assert_eq!(a.etag, etag_of(b"<p>hi</p>"));
        assert_ne!(a.etag, b.etag);
        assert!(a.etag.starts_with('"') && a.etag.len() == 34, "{}", a.etag);
    }

    #[test]
    fn a_missing_page_says_what_to_build() {
        let dir = tempfile::tempdir().unwrap();
        let root = WebRoot::load(&dir.path().join("dist")).unwrap();
        assert!(root.is_empty());
        assert!(root.missing().unwrap().contains(BUILD_COMMAND));
        std::fs::write(dir.path().join("app.js"), "x").unwrap();
        let root = WebRoot::load(dir.path()).unwrap();
        assert!(root.missing().unwrap().contains("index.html"));
        assert!(root.get("app.js").is_some());
    }

    #[test]
    fn too_many_or_too_large_files_are_refused_saying_which_limit() {
        let dir = tempfile::tempdir().unwrap();
        for i in 0..=MAX_FILES {
            std::fs::write(dir.path().join(format!("f{i}.js")), "x").unwrap();
        }
        let e = WebRoot::load(dir.path()).unwrap_err();
        assert!(
            matches!(e, WebRootError::TooManyFiles { max: 64, .. }),
            "{e}"
        );
        assert!(e.to_string().contains("--web-root"));
        let dir = tempfile::tempdir().unwrap();
        let big = std::fs::File::create(dir.path().join("big.wasm")).unwrap();
        big.set_len(MAX_BYTES + 1).unwrap();
        let e = WebRoot::load(dir.path()).unwrap_err();
        assert!(
            matches!(e, WebRootError::TooLarge { max_mib: 64, .. }),
            "{e}"
        );
        assert!(e.to_string().contains("64 MiB"));
    }
}
