//! The records on the web port: `GET /records` (every level with records:
//! JSON, or an HTML page of each level's top times for a browser) and
//! `GET /records/LEVEL` (a level's top N players, JSON; `LEVEL` is its
//! content hash, as `/web.json` names the level played). Requests pass the
//! web port's limits like every other.

use std::fmt::Write as _;

use axum::extract::Request;
use axum::http::{header, StatusCode};
use axum::response::Response;

use super::respond::{answer, text};
use crate::records::{LevelSummary, RecordStore, TopEntry};

/// Players listed by default, and at most (`?n=`).
pub const DEFAULT_TOP: u32 = 10;
/// Most levels the HTML page shows (the busiest first in the JSON all the
/// same).
pub const MAX_LEVELS_SHOWN: usize = 50;

/// The answer that says records are off.
fn off() -> Response {
    text(
        StatusCode::SERVICE_UNAVAILABLE,
        "this server keeps no records (--records off, or its database failed: see its log)\n"
            .into(),
    )
}

/// The answer to a failed query (the details are in the log).
fn failed(e: &crate::records::RecordsError) -> Response {
    tracing::warn!("records page: {e}");
    text(
        StatusCode::SERVICE_UNAVAILABLE,
        "the records database failed; try again later\n".into(),
    )
}

/// Whether the request asks for HTML (a browser) rather than JSON.
pub fn wants_html(request: &Request) -> bool {
    request
        .headers()
        .get(header::ACCEPT)
        .and_then(|v| v.to_str().ok())
        .is_some_and(|v| v.contains("text/html"))
}

/// `GET /records`.
pub async fn levels(store: Option<&RecordStore>, html: bool) -> Response {
    let Some(store) = store else {
        return off();
    };
    let levels = match store.levels().await {
        Ok(l) => l,
        Err(e) => return failed(&e),
    };
    if !html {
        let doc = serde_json::json!({ "levels": levels });
        return answer(StatusCode::OK, "application/json", doc.to_string());
    }
    let mut tops = Vec::new();
    for level in levels.iter().take(MAX_LEVELS_SHOWN) {
        match store.top(&level.hash, DEFAULT_TOP).await {
            Ok(top) => tops.push(top),
            Err(e) => return failed(&e),
        }
    }
    answer(
        StatusCode::OK,
        "text/html; charset=utf-8",
        page(&levels, &tops),
    )
}

/// `GET /records/LEVEL?n=N`.
pub async fn level(store: Option<&RecordStore>, hash: &str, query: Option<&str>) -> Response {
    let Some(store) = store else {
        return off();
    };
    if hash.len() != 64 || !hash.bytes().all(|b| b.is_ascii_hexdigit()) {
        return text(
            StatusCode::BAD_REQUEST,
            "a level is named by its content hash: 64 hex digits (GET /records lists them)\n"
                .into(),
        );
    }
    let n = match top_count(query) {
        Ok(n) => n,
        Err(message) => return text(StatusCode::BAD_REQUEST, message),
    };
    let hash = hash.to_ascii_lowercase();
    let levels = match store.levels().await {
        Ok(l) => l,
        Err(e) => return failed(&e),
    };
    let Some(summary) = levels.into_iter().find(|l| l.hash == hash) else {
        return text(StatusCode::NOT_FOUND, "no runs on that level yet\n".into());
    };
    match store.top(&hash, n).await {
        Ok(top) => {
            let doc = serde_json::json!({ "level": summary, "top": top });
            answer(StatusCode::OK, "application/json", doc.to_string())
        }
        Err(e) => failed(&e),
    }
}

/// `n` from the query: 1..=100, [`DEFAULT_TOP`] when absent.
fn top_count(query: Option<&str>) -> Result<u32, String> {
    let max = crate::records::store::MAX_TOP_QUERY;
    let Some(value) = query
        .into_iter()
        .flat_map(|q| q.split('&'))
        .find_map(|kv| kv.strip_prefix("n="))
    else {
        return Ok(DEFAULT_TOP);
    };
    match value.parse::<u32>() {
        Ok(n) if (1..=max).contains(&n) => Ok(n),
        _ => Err(format!("n must be 1..={max}\n")),
    }
}

/// A time as `m:ss.mmm`.
pub fn clock(millis: u64) -> String {
    format!(
        "{}:{:02}.{:03}",
        millis / 60_000,
        millis / 1000 % 60,
        millis % 1000
    )
}

/// `s` with HTML's special characters escaped.
fn escape(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    for c in s.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&#39;"),
            c => out.push(c),
        }
    }
    out
}

/// The HTML page: each level's top times.
fn page(levels: &[LevelSummary], tops: &[Vec<TopEntry>]) -> String {
    let mut html = String::from(
        "<!doctype html><html><head><meta charset=\"utf-8\"><title>ledge records</title>\
         <style>body{font-family:sans-serif;margin:2em}table{border-collapse:collapse}\
         td,th{padding:.2em .8em;text-align:left}td.t{font-variant-numeric:tabular-nums}\
         </style></head><body><h1>Records</h1>",
    );
    if levels.is_empty() {
        html.push_str("<p>No finished runs yet.</p>");
    }
    for (level, top) in levels.iter().zip(tops) {
        let _ = write!(
            html,
            "<h2>{}</h2><p>{} runs by {} players; level <code>{}</code> \
             (<a href=\"/records/{}\">JSON</a>)</p><table><tr><th>#</th><th>player</th>\
             <th>time</th><th>deaths</th><th>runs</th><th>replay</th></tr>",
            escape(&level.name),
            level.runs,
            level.players,
            &level.hash[..12.min(level.hash.len())],
            escape(&level.hash),
        );
        for e in top {
            let _ = write!(
                html,
                "<tr><td>{}</td><td>{}</td><td class=\"t\">{}</td><td>{}</td><td>{}</td>\
                 <td>{}</td></tr>",
                e.place,
                escape(&e.player),
                clock(e.millis),
                e.deaths,
                e.runs,
                replay_link(e.replay.as_deref()),
            );
        }
        html.push_str("</table>");
    }
    if levels.len() > MAX_LEVELS_SHOWN {
        let _ = write!(
            html,
            "<p>{} more levels: <a href=\"/records\">GET /records</a> as JSON lists them all.</p>",
            levels.len() - MAX_LEVELS_SHOWN
        );
    }
    html.push_str(
        "<p>\"watch\" plays a replay in this browser; the file's link plays in the game: \
         <code>ledge-client --replay</code> and the link's address.</p></body></html>",
    );
    html
}

/// The cell linking a run's replay: the file, and "watch", the page
/// playing it (`/?replay=ID`); only ids that are replay ids (the records
/// may hold anything).
fn replay_link(id: Option<&str>) -> String {
    match id.filter(|id| crate::replays::is_replay_id(id)) {
        Some(id) => {
            format!("<a href=\"/replays/{id}\">{id}</a> (<a href=\"/?replay={id}\">watch</a>)")
        }
        None => String::new(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn times_counts_and_names_are_shown_safely() {
        assert_eq!(clock(83_456), "1:23.456");
        assert_eq!(clock(9_000), "0:09.000");
        assert_eq!(top_count(None), Ok(10));
        assert_eq!(top_count(Some("n=3")), Ok(3));
        assert!(top_count(Some("n=0")).is_err() && top_count(Some("n=101")).is_err());
        let level = LevelSummary {
            hash: "ab".repeat(32),
            name: "<b>x</b>".into(),
            runs: 2,
            players: 1,
            best_millis: 9_000,
        };
        let top = vec![TopEntry {
            place: 1,
            player: "a&b".into(),
            millis: 9_000,
            ticks: 540,
            tick_rate: 60,
            deaths: 0,
            coins: 0,
            finished_at_ms: 0,
            runs: 2,
            replay: Some("0123456789abcdef".into()),
        }];
        let html = page(&[level], &[top]);
        assert!(html.contains("&lt;b&gt;x&lt;/b&gt;") && html.contains("a&amp;b"));
        assert!(html.contains("0:09.000") && !html.contains("<b>x"));
        assert!(html.contains("<a href=\"/replays/0123456789abcdef\">"));
        assert!(html.contains("<a href=\"/?replay=0123456789abcdef\">watch</a>"));
        assert_eq!(replay_link(Some("<script>")), "");
    }
}
