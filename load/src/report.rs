//! The results as a Markdown table (one row per run) and as CSV.

use std::fmt::Write as _;

use crate::run::RunResult;

/// Columns of the table and the CSV, in order.
const COLUMNS: [&str; 24] = [
    "bots",
    "clients",
    "rooms",
    "bot procs",
    "window s",
    "tick p50 ms",
    "tick p99 ms",
    "tick max ms",
    "missed ticks",
    "late wake-ups",
    "wake-up lateness p99 ms",
    "up B/s per client",
    "down B/s per client",
    "wire up B/s per client",
    "wire down B/s per client",
    "packets up/s per client",
    "packets down/s per client",
    "server CPU %",
    "server CPU ms per player-s",
    "server run-queue wait ms/s",
    "server peak RSS MiB",
    "bots CPU %",
    "connected / dropped",
    "inputs starved %",
];

fn ms(v: Option<f64>) -> String {
    v.map_or_else(|| "-".to_owned(), |s| format!("{:.3}", s * 1e3))
}

fn cells(r: &RunResult) -> [String; 24] {
    [
        r.bots.to_string(),
        r.client.clone(),
        r.rooms.to_string(),
        r.bot_processes.to_string(),
        format!("{:.0}", r.window_s),
        ms(r.tick_p50),
        ms(r.tick_p99),
        ms(r.tick_max),
        r.missed_ticks.to_string(),
        r.late_wakeups.to_string(),
        ms(r.lateness_p99),
        format!("{:.0}", r.up_bytes_per_client_s),
        format!("{:.0}", r.down_bytes_per_client_s),
        format!("{:.0}", r.wire_up_bytes_per_client_s),
        format!("{:.0}", r.wire_down_bytes_per_client_s),
        format!("{:.1}", r.packets_up_per_client_s),
        format!("{:.1}", r.packets_down_per_client_s),
        format!("{:.0}", r.server_cpu_pct),
        format!("{:.2}", r.cpu_ms_per_player_s()),
        format!("{:.0}", r.server_run_queue_wait_ms_s),
        format!("{:.1}", r.server_peak_rss_mib),
        format!("{:.0}", r.bot_cpu_pct),
        format!("{} / {}", r.connected, r.dropped),
        format!("{:.2}", r.starved_pct),
    ]
}

/// The Markdown header (two lines).
pub fn markdown_header() -> String {
    let mut s = format!("| {} |\n|", COLUMNS.join(" | "));
    for _ in COLUMNS {
        s.push_str("---:|");
    }
    s
}

/// One Markdown row.
pub fn markdown_row(r: &RunResult) -> String {
    format!("| {} |", cells(r).join(" | "))
}

/// A column name as a CSV header: words joined by `_`, symbols spelt out
/// (`up B/s per client` -> `up_B_per_s_per_client`).
fn csv_name(column: &str) -> String {
    column
        .replace("B/s", "B per s")
        .replace("ms/s", "ms per s")
        .replace("up/s", "up per s")
        .replace("down/s", "down per s")
        .replace('%', "pct")
        .split(|c: char| !c.is_ascii_alphanumeric())
        .filter(|w| !w.is_empty())
        .collect::<Vec<_>>()
        .join("_")
}

/// A CSV document: a header line and one line per result.
pub fn csv(results: &[RunResult]) -> String {
    let mut s = String::new();
    let header: Vec<String> = COLUMNS.iter().map(|c| csv_name(c)).collect();
    let _ = writeln!(
        s,
        "{},tick_mean_ms,ticks,load_start,load_end",
        header.join(",")
    );
    for r in results {
        let row: Vec<String> = cells(r).iter().map(|c| c.replace(" / ", "/")).collect();
        let _ = writeln!(
            s,
            "{},{},{},{:.2},{:.2}",
            row.join(","),
            ms(r.tick_mean),
            r.ticks,
            r.load.0,
            r.load.1
        );
    }
    s
}

/// Whether a result meets the goal: every bot stayed, no missed
/// tick, p99 tick at most `p99_goal` seconds.
pub fn meets_goal(r: &RunResult, p99_goal: f64) -> bool {
    r.dropped == 0
        && r.connected == r.bots as u64
        && r.missed_ticks == 0
        && r.tick_p99.is_some_and(|p| p <= p99_goal)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn result() -> RunResult {
        RunResult {
            bots: 256,
            client: "thin".into(),
            rooms: 16,
            bot_processes: 2,
            window_s: 30.02,
            ticks: 28_800,
            tick_p50: Some(0.000_123_4),
            tick_p99: Some(0.001_5),
            tick_max: Some(0.004),
            tick_mean: Some(0.000_2),
            missed_ticks: 0,
            late_wakeups: 3,
            lateness_p99: Some(0.001),
            up_bytes_per_client_s: 4100.4,
            down_bytes_per_client_s: 2500.6,
            wire_up_bytes_per_client_s: 1900.2,
            wire_down_bytes_per_client_s: 3900.7,
            packets_up_per_client_s: 30.04,
            packets_down_per_client_s: 31.96,
            server_cpu_pct: 55.2,
            server_run_queue_wait_ms_s: 12.3,
            server_peak_rss_mib: 40.3,
            bot_cpu_pct: 120.0,
            mean_players: 256.0,
            connected: 256,
            min_players: 256,
            dropped: 0,
            starved_pct: 0.5,
            load: (3.0, 3.5),
        }
    }

    #[test]
    fn rows_have_one_cell_per_column() {
        let row = markdown_row(&result());
        assert_eq!(
            row,
            "| 256 | thin | 16 | 2 | 30 | 0.123 | 1.500 | 4.000 | 0 | 3 | 1.000 | 4100 | 2501 \
             | 1900 | 3901 | 30.0 | 32.0 | 55 | 2.16 | 12 | 40.3 | 120 | 256 / 0 | 0.50 |"
        );
        let header = markdown_header();
        let cols = header.lines().next().unwrap().matches('|').count();
        assert_eq!(cols, row.matches('|').count());
        let csv = csv(&[result()]);
        let lines: Vec<&str> = csv.lines().collect();
        assert_eq!(lines.len(), 2);
        assert_eq!(
            lines[0].split(',').count(),
            lines[1].split(',').count(),
            "{csv}"
        );
        assert!(lines[1].starts_with("256,thin,16,2,30,0.123,1.500,"));
        assert!(lines[0].starts_with("bots,clients,rooms,bot_procs,window_s,tick_p50_ms,"));
        assert!(lines[0].contains(",up_B_per_s_per_client,"), "{}", lines[0]);
        assert!(lines[0].contains(",server_run_queue_wait_ms_per_s,"));
        assert!(
            lines[0].contains(",packets_up_per_s_per_client,"),
            "{}",
            lines[0]
        );
        assert!(
            lines[0].contains(",server_CPU_ms_per_player_s,"),
            "{}",
            lines[0]
        );
        assert!(lines[0].contains(",connected_dropped,inputs_starved_pct,"));
        assert!(lines[1].ends_with(",0.200,28800,3.00,3.50"));
    }

    #[test]
    fn the_goal_needs_every_bot_no_missed_tick_and_a_short_p99() {
        assert!(meets_goal(&result(), 0.002));
        assert!(!meets_goal(&result(), 0.001));
        let missed = RunResult {
            missed_ticks: 1,
            ..result()
        };
        assert!(!meets_goal(&missed, 0.002));
        let dropped = RunResult {
            dropped: 1,
            ..result()
        };
        assert!(!meets_goal(&dropped, 0.002));
    }
}
