//! What the web port answers when one of its limits says no
//! ([`crate::web::guard`]): 429 (413 for a body, 503 when too many
//! addresses are active) with `Retry-After` and a line saying which limit,
//! never a silent drop. A connection over its address's cap is answered
//! straight on the socket, before any of its request is read.

use std::time::Duration;

use axum::http::{header, HeaderValue, StatusCode};
use axum::response::Response;
use tokio::io::{AsyncReadExt, AsyncWriteExt};
use tokio::net::TcpStream;

use super::guard::{Limited, WebRefusal};

/// How long a refused connection is given to take its answer.
pub const REFUSAL_LINGER: Duration = Duration::from_secs(1);
/// Most bytes read (and dropped) from a refused connection so closing it
/// does not reset it before the answer is read.
const REFUSAL_DRAIN: usize = 16 * 1024;

/// The status of a refusal.
pub fn status(reason: WebRefusal) -> StatusCode {
    match reason {
        WebRefusal::Body => StatusCode::PAYLOAD_TOO_LARGE,
        WebRefusal::Addresses => StatusCode::SERVICE_UNAVAILABLE,
        WebRefusal::Connections | WebRefusal::Requests | WebRefusal::Downloads => {
            StatusCode::TOO_MANY_REQUESTS
        }
    }
}

/// What a refused client is told.
pub fn message(reason: WebRefusal) -> &'static str {
    match reason {
        WebRefusal::Connections => {
            "too many connections from your address: close some and try again\n"
        }
        WebRefusal::Requests => "too many requests from your address: wait and try again\n",
        WebRefusal::Downloads => {
            "too many downloads from your address: let the others finish and try again\n"
        }
        WebRefusal::Body => "this server takes no request bodies\n",
        WebRefusal::Addresses => "the server is busy: try again shortly\n",
    }
}

/// Whole seconds to wait, at least 1 (`Retry-After` counts seconds).
fn retry_secs(after: Duration) -> u64 {
    after.as_secs_f64().ceil().max(1.0) as u64
}

/// The response to a refused request; it closes the connection.
pub fn limited_response(limited: Limited) -> Response {
    let mut response = Response::new(message(limited.reason).into());
    *response.status_mut() = status(limited.reason);
    let headers = response.headers_mut();
    headers.insert(header::RETRY_AFTER, retry_secs(limited.retry_after).into());
    headers.insert(
        header::CONTENT_TYPE,
        HeaderValue::from_static("text/plain; charset=utf-8"),
    );
    headers.insert(header::CACHE_CONTROL, HeaderValue::from_static("no-store"));
    headers.insert(header::CONNECTION, HeaderValue::from_static("close"));
    response
}

/// The bytes of [`limited_response`] as HTTP/1.1, for a connection that is
/// refused before its request is read.
pub fn refusal_bytes(limited: Limited) -> Vec<u8> {
    let status = status(limited.reason);
    let body = message(limited.reason);
    format!(
        "HTTP/1.1 {} {}\r\nRetry-After: {}\r\nContent-Type: text/plain; charset=utf-8\r\n\
         Content-Length: {}\r\nCache-Control: no-store\r\nConnection: close\r\n\r\n{body}",
        status.as_u16(),
        status.canonical_reason().unwrap_or(""),
        retry_secs(limited.retry_after),
        body.len(),
    )
    .into_bytes()
}

/// Answers `stream` with the refusal and closes it, within
/// [`REFUSAL_LINGER`] whatever the peer does.
pub async fn refuse_connection(mut stream: TcpStream, limited: Limited) {
    let answer = async {
        stream.write_all(&refusal_bytes(limited)).await?;
        stream.shutdown().await?;
        // Read what the peer sent until it closes, so the close is not a
        // reset that could discard the answer.
        let mut drained = 0;
        let mut buf = [0u8; 4096];
        while drained < REFUSAL_DRAIN {
            match stream.read(&mut buf).await? {
                0 => break,
                n => drained += n,
            }
        }
        Ok::<_, std::io::Error>(())
    };
    let _ = tokio::time::timeout(REFUSAL_LINGER, answer).await;
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn refusals_say_which_limit_and_when_to_come_back() {
        let limited = Limited {
            reason: WebRefusal::Requests,
            retry_after: Duration::from_millis(1200),
        };
        let r = limited_response(limited);
        assert_eq!(r.status(), StatusCode::TOO_MANY_REQUESTS);
        assert_eq!(r.headers()[header::RETRY_AFTER], "2");
        let raw = String::from_utf8(refusal_bytes(Limited {
            reason: WebRefusal::Connections,
            retry_after: Duration::ZERO,
        }))
        .unwrap();
        assert!(
            raw.starts_with("HTTP/1.1 429 Too Many Requests\r\n"),
            "{raw}"
        );
        assert!(raw.contains("\r\nRetry-After: 1\r\n"));
        let (head, body) = raw.split_once("\r\n\r\n").unwrap();
        assert!(head.contains(&format!("Content-Length: {}", body.len())));
        assert!(body.contains("too many connections"));
        assert_eq!(status(WebRefusal::Body), StatusCode::PAYLOAD_TOO_LARGE);
        assert_eq!(
            status(WebRefusal::Addresses),
            StatusCode::SERVICE_UNAVAILABLE
        );
    }
}
