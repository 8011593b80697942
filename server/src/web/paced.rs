//! Download bodies sent at the pace the web port's limits allow
//! ([`crate::web::guard`]): in chunks, each waiting until its address and
//! the uplink have the budget for it.

use std::convert::Infallible;
use std::time::Instant;

use axum::body::Body;
use bytes::Bytes;
use prometheus_client::metrics::counter::Counter;

use super::guard::DownloadPermit;

/// Bytes sent at a time: small enough that pacing is smooth (a chunk is
/// 10 ms at 26 Mbit/s), large enough that the wake-ups cost nothing.
pub const CHUNK: usize = 32 * 1024;

/// `bytes` as a body sent in [`CHUNK`]s paced by `permit` (held until the
/// body is sent or dropped), each counted in `sent`.
pub fn paced_body(bytes: Bytes, permit: DownloadPermit, sent: Counter) -> Body {
    let stream = futures_util::stream::unfold(
        (bytes, permit, sent),
        |(mut rest, permit, sent)| async move {
            if rest.is_empty() {
                return None;
            }
            let chunk = rest.split_to(rest.len().min(CHUNK));
            let wait = permit.pace(chunk.len(), Instant::now());
            if !wait.is_zero() {
                tokio::time::sleep(wait).await;
            }
            sent.inc_by(chunk.len() as u64);
            Some((Ok::<_, Infallible>(chunk), (rest, permit, sent)))
        },
    );
    Body::from_stream(stream)
}
