//! One plain HTTP GET to a ledge server's web port (ureq: no TLS, no
//! compression, no redirects, no proxy: straight to the server, as the
//! game's own connection goes): the body read up to a bound and never
//! more, refused before reading when the server announces more; every
//! failure in words, with what to do.

use std::io::Read;
use std::time::Duration;

use anyhow::bail;

/// How long connecting may take.
pub const CONNECT_TIMEOUT: Duration = Duration::from_secs(10);

/// How long the whole request may take (a replay is at most 32 MiB: on a
/// slow link, minutes).
pub const REQUEST_TIMEOUT: Duration = Duration::from_secs(300);

/// The body of `url`, at most `max` bytes. `what` names the thing fetched
/// in messages ("replay", "level"); `not_found` says what to do when the
/// server has no such thing.
pub fn get(url: &str, max: u64, what: &str, not_found: &str) -> anyhow::Result<Vec<u8>> {
    let agent: ureq::Agent = ureq::Agent::config_builder()
        .http_status_as_error(false)
        .max_redirects(0)
        .proxy(None)
        .timeout_connect(Some(CONNECT_TIMEOUT))
        .timeout_global(Some(REQUEST_TIMEOUT))
        .user_agent(concat!("ledge-client/", env!("CARGO_PKG_VERSION")))
        .build()
        .into();
    let response = agent
        .get(url)
        .call()
        .map_err(|e| unreachable(url, what, e))?;
    let status = response.status();
    match status.as_u16() {
        200 => {}
        404 => bail!("{url}: the server has no such {what} (404 Not Found): {not_found}"),
        429 => {
            let wait = response
                .headers()
                .get("retry-after")
                .and_then(|v| v.to_str().ok())
                .and_then(|v| v.trim().parse::<u64>().ok())
                .map_or_else(|| "a little while".to_owned(), |s| format!("{s} s"));
            bail!(
                "{url}: the server refuses more requests from this address for now \
                 (429 Too Many Requests): try again in {wait}"
            );
        }
        _ => bail!(
            "{url}: the server answered {} {} instead of the {what}: check the address \
             (it is the server's web port, --web-bind) and try again later",
            status.as_u16(),
            status.canonical_reason().unwrap_or("")
        ),
    }
    let body = response.into_body();
    if let Some(len) = body.content_length().filter(|&len| len > max) {
        bail!(
            "{url}: the server offers {len} bytes, more than a {what} can be ({max} bytes): \
             refused without reading it"
        );
    }
    let mut bytes = Vec::new();
    body.into_reader()
        .take(max + 1)
        .read_to_end(&mut bytes)
        .map_err(|e| anyhow::anyhow!("{url}: the {what}'s download broke off: {e}: try again"))?;
    if bytes.len() as u64 > max {
        bail!(
            "{url}: the server sent more than a {what} can be ({max} bytes): refused; \
             is this a ledge server?"
        );
    }
    Ok(bytes)
}

/// Why `url` could not be asked, and what to check.
fn unreachable(url: &str, what: &str, e: ureq::Error) -> anyhow::Error {
    let why = match &e {
        ureq::Error::HostNotFound => "its host name is not known".to_owned(),
        ureq::Error::Timeout(_) => "it did not answer in time".to_owned(),
        ureq::Error::Io(io) if io.kind() == std::io::ErrorKind::ConnectionRefused => {
            "nothing listens on that port".to_owned()
        }
        other => other.to_string(),
    };
    anyhow::anyhow!(
        "cannot fetch the {what} from {url}: {why}: check the address and port (the \
         server's web port, --web-bind 8080 prints it) and that the server is running"
    )
}
