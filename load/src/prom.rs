//! Reading the server's Prometheus endpoint: one HTTP GET over plain TCP
//! (with timeouts) and a parser of the text exposition format, enough for
//! the series `ledge-server` serves (counters, gauges, classic histograms).

use std::io::{Read, Write};
use std::net::{SocketAddr, TcpStream};
use std::time::Duration;

use anyhow::{bail, Context};

use crate::quantile::Buckets;

/// Connect, write and read timeout of one scrape.
pub const SCRAPE_TIMEOUT: Duration = Duration::from_secs(5);
/// Largest response read (the server's is tens of kilobytes).
const MAX_RESPONSE: u64 = 32 << 20;

/// One sample line: `name{label="value",...} value`.
#[derive(Debug, Clone, PartialEq)]
pub struct Sample {
    /// Metric name, with its suffix (`_total`, `_bucket`, ...).
    pub name: String,
    /// Labels in the order given.
    pub labels: Vec<(String, String)>,
    /// The value.
    pub value: f64,
}

impl Sample {
    /// The value of label `key`, if present.
    pub fn label(&self, key: &str) -> Option<&str> {
        self.labels
            .iter()
            .find(|(k, _)| k == key)
            .map(|(_, v)| v.as_str())
    }
}

/// Every sample of one scrape.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Scrape {
    /// Samples in the order served.
    pub samples: Vec<Sample>,
}

impl Scrape {
    /// Parses the text exposition format; comments and blank lines are
    /// skipped, a malformed sample line is an error.
    pub fn parse(text: &str) -> anyhow::Result<Scrape> {
        let mut samples = Vec::new();
        for (i, line) in text.lines().enumerate() {
            let line = line.trim();
            if line.is_empty() || line.starts_with('#') {
                continue;
            }
            let sample =
                parse_sample(line).with_context(|| format!("metrics line {}: {line:?}", i + 1))?;
            samples.push(sample);
        }
        Ok(Scrape { samples })
    }

    /// Sum of every series named `name` (all label sets); 0 when absent.
    pub fn sum(&self, name: &str) -> f64 {
        self.samples
            .iter()
            .filter(|s| s.name == name)
            .map(|s| s.value)
            .sum()
    }

    /// The value of `name` with label `key` = `value`, if served.
    pub fn get(&self, name: &str, key: &str, value: &str) -> Option<f64> {
        self.samples
            .iter()
            .find(|s| s.name == name && s.label(key) == Some(value))
            .map(|s| s.value)
    }

    /// The cumulative buckets of histogram `name` (the `name_bucket`
    /// series, summed over any other labels), in increasing bound order,
    /// `+Inf` last. Empty when the histogram is not served.
    pub fn histogram(&self, name: &str) -> anyhow::Result<Buckets> {
        let series = format!("{name}_bucket");
        let mut bounds: Vec<(f64, f64)> = Vec::new();
        for s in self.samples.iter().filter(|s| s.name == series) {
            let le = s
                .label("le")
                .with_context(|| format!("{series} without an le label"))?;
            let le = parse_float(le).with_context(|| format!("{series} le={le:?}"))?;
            match bounds.iter_mut().find(|(b, _)| *b == le) {
                Some((_, count)) => *count += s.value,
                None => bounds.push((le, s.value)),
            }
        }
        bounds.sort_by(|a, b| a.0.total_cmp(&b.0));
        Buckets::from_cumulative(&bounds)
    }
}

/// Parses a float as the exposition format writes it (`+Inf`, `-Inf`,
/// `NaN` included).
fn parse_float(text: &str) -> anyhow::Result<f64> {
    match text {
        "+Inf" | "Inf" => Ok(f64::INFINITY),
        "-Inf" => Ok(f64::NEG_INFINITY),
        "NaN" => Ok(f64::NAN),
        _ => text
            .parse()
            .with_context(|| format!("not a number: {text:?}")),
    }
}

fn parse_sample(line: &str) -> anyhow::Result<Sample> {
    let name_end = line
        .find(|c: char| c == '{' || c.is_whitespace())
        .context("no value")?;
    let name = line[..name_end].to_owned();
    if name.is_empty() {
        bail!("no metric name");
    }
    let mut rest = &line[name_end..];
    let mut labels = Vec::new();
    if let Some(after) = rest.strip_prefix('{') {
        let (parsed, tail) = parse_labels(after)?;
        labels = parsed;
        rest = tail;
    }
    // The value, then an optional timestamp or exemplar (ignored).
    let value = rest.split_whitespace().next().context("no value")?;
    Ok(Sample {
        name,
        labels,
        value: parse_float(value)?,
    })
}

/// Parses `key="value",...}` and returns the labels and what follows `}`.
fn parse_labels(mut text: &str) -> anyhow::Result<(Vec<(String, String)>, &str)> {
    let mut labels = Vec::new();
    loop {
        text = text.trim_start_matches([' ', ',']);
        if let Some(tail) = text.strip_prefix('}') {
            return Ok((labels, tail));
        }
        let eq = text.find('=').context("label without '='")?;
        let key = text[..eq].trim().to_owned();
        text = text[eq + 1..]
            .strip_prefix('"')
            .context("label value not quoted")?;
        let mut value = String::new();
        let mut chars = text.char_indices();
        let end = loop {
            match chars.next() {
                Some((i, '"')) => break i,
                Some((_, '\\')) => match chars.next() {
                    Some((_, 'n')) => value.push('\n'),
                    Some((_, c)) => value.push(c),
                    None => bail!("unterminated escape"),
                },
                Some((_, c)) => value.push(c),
                None => bail!("unterminated label value"),
            }
        };
        labels.push((key, value));
        text = &text[end + 1..];
    }
}

/// `GET /metrics` from `addr` and parses the answer.
pub fn scrape(addr: SocketAddr) -> anyhow::Result<Scrape> {
    let body = fetch(addr).with_context(|| format!("scraping http://{addr}/metrics"))?;
    Scrape::parse(&body).with_context(|| format!("parsing the metrics of {addr}"))
}

fn fetch(addr: SocketAddr) -> anyhow::Result<String> {
    let mut stream = TcpStream::connect_timeout(&addr, SCRAPE_TIMEOUT).context("connecting")?;
    stream.set_read_timeout(Some(SCRAPE_TIMEOUT))?;
    stream.set_write_timeout(Some(SCRAPE_TIMEOUT))?;
    write!(
        stream,
        "GET /metrics HTTP/1.1\r\nHost: {addr}\r\nConnection: close\r\n\r\n"
    )
    .context("sending the request")?;
    let mut response = Vec::new();
    stream
        .take(MAX_RESPONSE)
        .read_to_end(&mut response)
        .context("reading the response")?;
    let response = String::from_utf8(response).context("response is not UTF-8")?;
    let (head, body) = response
        .split_once("\r\n\r\n")
        .context("response without a header end")?;
    let status = head.lines().next().unwrap_or_default();
    if !status.contains(" 200 ") {
        bail!("HTTP status {status:?}");
    }
    Ok(body.to_owned())
}

#[cfg(test)]
mod tests {
    use super::*;

    const TEXT: &str = r#"# HELP ledge_players Players in the room.
# TYPE ledge_players gauge
ledge_players{room="room-1"} 3
ledge_players{room="room-2"} 4
# TYPE ledge_missed_ticks counter
ledge_missed_ticks_total{room="room-1"} 2
ledge_odd{a="x\"y",b="c\\d"} 1.5e-3 1700000000
ledge_bare 7
# TYPE h histogram
h_sum 0.5
h_count 3
h_bucket{room="a",le="0.001"} 1
h_bucket{room="b",le="0.001"} 0
h_bucket{room="a",le="0.01"} 2
h_bucket{room="b",le="0.01"} 1
h_bucket{room="a",le="+Inf"} 2
h_bucket{room="b",le="+Inf"} 1
# EOF
"#;

    #[test]
    fn parses_samples_labels_and_escapes() {
        let s = Scrape::parse(TEXT).unwrap();
        assert_eq!(s.sum("ledge_players"), 7.0);
        assert_eq!(s.get("ledge_players", "room", "room-2"), Some(4.0));
        assert_eq!(s.sum("ledge_missed_ticks_total"), 2.0);
        assert_eq!(s.get("ledge_odd", "a", "x\"y"), Some(1.5e-3));
        assert_eq!(s.get("ledge_odd", "b", "c\\d"), Some(1.5e-3));
        assert_eq!(s.sum("ledge_bare"), 7.0);
        assert_eq!(s.sum("absent"), 0.0);
    }

    #[test]
    fn histogram_buckets_are_summed_over_labels() {
        let s = Scrape::parse(TEXT).unwrap();
        let h = s.histogram("h").unwrap();
        assert_eq!(h.total(), 3);
        assert_eq!(h.counts(), &[1, 2, 0]);
        assert_eq!(h.bounds()[..2], [0.001, 0.01]);
        assert!(s.histogram("absent").unwrap().is_empty());
    }

    #[test]
    fn malformed_lines_are_errors() {
        for bad in [
            "x{a=\"b} 1",
            "x{a=b} 1",
            "x{a=\"b\"}",
            "x one",
            "{a=\"b\"} 1",
        ] {
            assert!(Scrape::parse(bad).is_err(), "{bad:?} parsed");
        }
    }
}
