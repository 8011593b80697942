//! CPU time and peak memory of a process from Linux's `/proc`, and the
//! machine's load average.
//!
//! CPU: `utime + stime` of `/proc/<pid>/stat` (all threads), in clock
//! ticks; two readings over a window give the CPU used, as a percentage of
//! one core. Peak memory: `VmHWM` of `/proc/<pid>/status`, the resident set's
//! high-water mark.

use std::fs;
use std::process::Command;

use anyhow::{bail, Context};

/// Clock ticks per second of `/proc/<pid>/stat` (`getconf CLK_TCK`; 100
/// when that fails, which is what Linux uses on every common platform).
pub fn clock_ticks_per_second() -> u64 {
    Command::new("getconf")
        .arg("CLK_TCK")
        .output()
        .ok()
        .filter(|o| o.status.success())
        .and_then(|o| String::from_utf8(o.stdout).ok())
        .and_then(|s| s.trim().parse().ok())
        .filter(|&t: &u64| t > 0)
        .unwrap_or(100)
}

/// User plus system CPU time from the text of `/proc/<pid>/stat`, in
/// clock ticks.
pub fn parse_cpu_ticks(stat: &str) -> anyhow::Result<u64> {
    // The command name is in parentheses and may hold spaces or ')'.
    let after = stat
        .rfind(')')
        .map(|i| &stat[i + 1..])
        .context("no ')' after the command name")?;
    let fields: Vec<&str> = after.split_whitespace().collect();
    // Fields after the name start at field 3 (state); utime is 14, stime 15.
    if fields.len() < 13 {
        bail!("only {} fields after the command name", fields.len());
    }
    let utime: u64 = fields[11].parse().context("utime")?;
    let stime: u64 = fields[12].parse().context("stime")?;
    Ok(utime + stime)
}

/// `VmHWM` (peak resident set) from the text of `/proc/<pid>/status`, in
/// KiB.
pub fn parse_vm_hwm_kib(status: &str) -> anyhow::Result<u64> {
    let line = status
        .lines()
        .find_map(|l| l.strip_prefix("VmHWM:"))
        .context("no VmHWM line")?;
    let mut parts = line.split_whitespace();
    let value: u64 = parts.next().context("VmHWM without a value")?.parse()?;
    match parts.next() {
        Some("kB") => Ok(value),
        other => bail!("VmHWM in unexpected unit {other:?}"),
    }
}

/// CPU time of process `pid` so far, in clock ticks.
pub fn cpu_ticks(pid: u32) -> anyhow::Result<u64> {
    let path = format!("/proc/{pid}/stat");
    let text = fs::read_to_string(&path).with_context(|| format!("reading {path}"))?;
    parse_cpu_ticks(&text).with_context(|| format!("parsing {path}"))
}

/// Peak resident memory of process `pid` so far, in KiB.
pub fn vm_hwm_kib(pid: u32) -> anyhow::Result<u64> {
    let path = format!("/proc/{pid}/status");
    let text = fs::read_to_string(&path).with_context(|| format!("reading {path}"))?;
    parse_vm_hwm_kib(&text).with_context(|| format!("parsing {path}"))
}

/// Time spent runnable but waiting for a CPU, from the text of a
/// `/proc/<pid>/task/<tid>/schedstat` (`run_ns wait_ns timeslices`), in
/// nanoseconds.
pub fn parse_run_queue_wait_ns(schedstat: &str) -> anyhow::Result<u64> {
    let wait = schedstat
        .split_whitespace()
        .nth(1)
        .context("schedstat has fewer than 2 fields")?;
    wait.parse()
        .with_context(|| format!("schedstat wait {wait:?}"))
}

/// Run-queue wait of all of process `pid`'s threads so far, in
/// nanoseconds: how long they were ready to run while every CPU was busy
/// (with other processes, or each other). Threads that have exited are not
/// counted (the server's threads live as long as it does).
pub fn run_queue_wait_ns(pid: u32) -> anyhow::Result<u64> {
    let dir = format!("/proc/{pid}/task");
    let mut total = 0;
    for entry in fs::read_dir(&dir).with_context(|| format!("listing {dir}"))? {
        let path = entry?.path().join("schedstat");
        // A thread may end between the listing and the read.
        if let Ok(text) = fs::read_to_string(&path) {
            total += parse_run_queue_wait_ns(&text)
                .with_context(|| format!("parsing {}", path.display()))?;
        }
    }
    Ok(total)
}

/// The 1, 5 and 15 minute load averages (`/proc/loadavg`).
pub fn load_average() -> anyhow::Result<[f64; 3]> {
    let text = fs::read_to_string("/proc/loadavg").context("reading /proc/loadavg")?;
    let mut fields = text.split_whitespace().map(str::parse::<f64>);
    let mut next = || -> anyhow::Result<f64> {
        fields
            .next()
            .context("/proc/loadavg too short")?
            .context("/proc/loadavg")
    };
    Ok([next()?, next()?, next()?])
}

/// The CPU model (first `model name` of `/proc/cpuinfo`), if readable.
pub fn cpu_model() -> Option<String> {
    let text = fs::read_to_string("/proc/cpuinfo").ok()?;
    text.lines()
        .find_map(|l| l.strip_prefix("model name"))
        .and_then(|l| l.split_once(':'))
        .map(|(_, model)| model.trim().to_owned())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cpu_ticks_skip_a_command_name_with_spaces_and_parens() {
        let stat = "4242 (ledge (x) srv) S 1 4242 4242 0 -1 4194560 1234 0 0 0 \
                    150 37 0 0 20 0 3 0 1000 123456 789 18446744073709551615";
        assert_eq!(parse_cpu_ticks(stat).unwrap(), 187);
        assert!(parse_cpu_ticks("4242 (x) S 1 2").is_err());
        assert!(parse_cpu_ticks("no parens").is_err());
    }

    #[test]
    fn vm_hwm_is_read_in_kib() {
        let status =
            "Name:\tledge-server\nVmPeak:\t  999 kB\nVmHWM:\t   20480 kB\nVmRSS:\t 100 kB\n";
        assert_eq!(parse_vm_hwm_kib(status).unwrap(), 20480);
        assert!(parse_vm_hwm_kib("VmRSS: 1 kB").is_err());
        assert!(parse_vm_hwm_kib("VmHWM: 1 MB").is_err());
    }

    #[test]
    fn run_queue_wait_is_the_second_schedstat_field() {
        assert_eq!(parse_run_queue_wait_ns("123 4567 8\n").unwrap(), 4567);
        assert!(parse_run_queue_wait_ns("123").is_err());
        assert!(parse_run_queue_wait_ns("1 x 2").is_err());
    }

    #[test]
    fn this_process_has_cpu_time_and_memory() {
        let pid = std::process::id();
        // Burn a little CPU so the reading cannot be a constant.
        let start = cpu_ticks(pid).unwrap();
        let t0 = std::time::Instant::now();
        let mut x = 0u64;
        while cpu_ticks(pid).unwrap() == start && t0.elapsed().as_secs() < 10 {
            for i in 0..100_000u64 {
                x = std::hint::black_box(x.wrapping_mul(31).wrapping_add(i));
            }
        }
        assert!(cpu_ticks(pid).unwrap() > start);
        assert!(vm_hwm_kib(pid).unwrap() > 100);
        assert!(clock_ticks_per_second() > 0);
        assert!(load_average().unwrap()[0] >= 0.0);
        // Readable for every thread (the value itself depends on the load).
        run_queue_wait_ns(pid).unwrap();
    }
}
