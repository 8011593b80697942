//! Failures told plainly by the real `ledge-client` binary: a session that
//! fails shows why in its window, wrapped to the window (checked in the
//! screenshot's pixels at 480x270), says the same once on stderr, and exits
//! non-zero; a server that cannot be reached says what to check; a name
//! over the limit is a command-line error naming the limit; `--help` lists
//! the exit codes.
//!
//! The window tests run under `xvfb-run` (skipped with a loud notice when
//! it is missing, failing when `CI=true`).

use crate::common;

use std::path::Path;
use std::process::{Command, Output};
use std::time::Duration;

use common::{pair, run_to_end, screenshot_dir, xvfb_or_skip, Png, TestServer};
use ledge_client::connect;
use serde_json::Value;

/// The client must have exited within this time.
const CLIENT_TIMEOUT: Duration = Duration::from_secs(90);
/// Exit code of a failed session.
const EXIT_FAILED: i32 = 1;
/// Exit code of a command-line error (clap's).
const EXIT_USAGE: i32 = 2;
/// The window of the screenshot test.
const WINDOW: (u32, u32) = (480, 270);

/// The client binary under `xvfb`, with no configuration of the user's.
fn windowed(xvfb: &Path, home: &Path) -> Command {
    let mut command = Command::new(xvfb);
    command
        .args(["-a", "-s", "-screen 0 640x480x24"])
        .arg(env!("CARGO_BIN_EXE_ledge-client"))
        .env("XDG_CONFIG_HOME", home)
        .env("HOME", home)
        .env("LIBGL_ALWAYS_SOFTWARE", "1")
        .env("RUST_LOG", "warn");
    command
}

/// The lines of `out`'s stderr that the client wrote itself (not logs).
fn told(out: &Output) -> Vec<String> {
    String::from_utf8_lossy(&out.stderr)
        .lines()
        .filter(|l| l.starts_with("ledge-client: "))
        .map(str::to_owned)
        .collect()
}

fn close(a: [u8; 3], b: [u8; 3]) -> bool {
    a.iter().zip(b).all(|(&x, y)| x.abs_diff(y) <= 3)
}

#[test]
fn a_refused_join_is_shown_inside_a_small_window_and_on_stderr() {
    let Some(xvfb) = xvfb_or_skip("the failure screenshot test") else {
        return;
    };
    // A server with room for one player, taken: the client is refused.
    let server = TestServer::start_with(|config| config.max_players = 1);
    let first = server.block_on(async {
        connect(server.addr, "localhost", server.fingerprint, "first")
            .await
            .expect("the first player is welcomed")
    });

    // LEDGE_SCREENSHOT_DIR keeps the picture (to look at it).
    let tmp = tempfile::tempdir().unwrap();
    let dir = screenshot_dir(tmp.path());
    let png_path = dir.join("failure.png");
    let mut command = windowed(&xvfb, tmp.path());
    command
        .args(["--connect", &server.addr.to_string()])
        .args(["--cert-hash", &server.fingerprint.to_string()])
        .args(["--name", "late"])
        .args(["--exit-after-ticks", "30"])
        .arg("--screenshot")
        .arg(&png_path)
        .args(["--window", &format!("{}x{}", WINDOW.0, WINDOW.1)]);
    let out = run_to_end(command, CLIENT_TIMEOUT);
    server.block_on(first.close());
    let addr = server.addr;
    server.stop();
    let stderr = String::from_utf8_lossy(&out.stderr);

    // Non-zero, told once on stderr.
    assert_eq!(
        out.status.code(),
        Some(EXIT_FAILED),
        "a refused join exits with {EXIT_FAILED}; stderr:\n{stderr}"
    );
    let told = told(&out);
    assert_eq!(told.len(), 1, "told once: {stderr}");
    let json: Value = serde_json::from_str(
        &std::fs::read_to_string(dir.join("failure.png.json"))
            .expect("the screenshot's JSON exists"),
    )
    .expect("valid JSON");
    let failure = &json["failure"];
    let message = failure["message"].as_str().expect("a failure in the JSON");
    // The window says what stderr says, which says what to do.
    assert_eq!(told[0], format!("ledge-client: {message}"));
    for needle in [
        &format!("cannot join {addr}: "),
        "the room is full",
        "Try again later",
    ] {
        assert!(message.contains(needle), "{needle:?} missing: {message}");
    }
    assert!(!message.contains("Some(") && !message.contains("None"));

    // Wrapped: several lines, holding the message's words and the way out.
    let lines: Vec<&str> = failure["lines"]
        .as_array()
        .unwrap()
        .iter()
        .map(|l| l.as_str().unwrap())
        .collect();
    assert!(lines.len() >= 3, "not wrapped at 480 px: {lines:?}");
    let words: Vec<&str> = lines.iter().flat_map(|l| l.split_whitespace()).collect();
    let expected: Vec<&str> = message.split_whitespace().chain(["Esc", "quits"]).collect();
    assert_eq!(words, expected);

    // The picture: the window's size; the panel inside it, where the JSON
    // says; every white text pixel on the panel, off the window's edges.
    let img = Png::load(&png_path);
    assert_eq!((img.width, img.height), WINDOW, "{json}");
    assert_eq!(pair(&json["screen"]), (480.0, 270.0));
    let p: Vec<f64> = failure["panel"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_f64().unwrap())
        .collect();
    let (px, py, pw, ph) = (p[0], p[1], p[2], p[3]);
    let (w, h) = (f64::from(WINDOW.0), f64::from(WINDOW.1));
    assert!(
        px >= 8.0 && py >= 8.0 && px + pw <= w - 8.0 && py + ph <= h - 8.0,
        "panel {p:?} not inside the {w}x{h} window"
    );
    let inside = |x: u32, y: u32| {
        let (x, y) = (f64::from(x) + 0.5, f64::from(y) + 0.5);
        x >= px - 1.0 && x <= px + pw + 1.0 && y >= py - 1.0 && y <= py + ph + 1.0
    };
    let panel_colour = {
        let c = failure["panel_color"].as_array().unwrap();
        [0, 1, 2].map(|i| c[i].as_u64().unwrap() as u8)
    };
    let (mut panel, mut stray_panel) = (0u32, Vec::new());
    let (mut text, mut stray_text) = (0u32, Vec::new());
    let (mut left, mut right) = (u32::MAX, 0);
    let mut text_rows = vec![false; img.height as usize];
    for y in 0..img.height {
        for x in 0..img.width {
            let [r, g, b, _] = img.at(x, y);
            if close([r, g, b], panel_colour) {
                panel += 1;
                if !inside(x, y) {
                    stray_panel.push((x, y));
                }
            }
            if r.min(g).min(b) >= 230 {
                text += 1;
                text_rows[y as usize] = true;
                (left, right) = (left.min(x), right.max(x));
                if !inside(x, y) {
                    stray_text.push((x, y));
                }
            }
        }
    }
    assert!(
        f64::from(panel) >= 0.5 * pw * ph,
        "the panel colour {panel_colour:?} covers only {panel} px of {pw}x{ph}"
    );
    assert!(
        stray_panel.is_empty(),
        "panel colour outside: {stray_panel:?}"
    );
    assert!(text >= 300, "only {text} white text pixels");
    assert!(
        stray_text.is_empty(),
        "text outside the panel: {stray_text:?}"
    );
    assert!(
        left >= 16 && right + 16 < img.width,
        "text from x = {left} to {right}: too close to the edges"
    );
    // Several bands of white rows: the lines are drawn one under the
    // other.
    let bands = text_rows
        .windows(2)
        .filter(|pair| !pair[0] && pair[1])
        .count()
        + usize::from(text_rows[0]);
    assert!(bands >= 3, "{bands} bands of text rows for {lines:?}");
}

#[test]
fn an_unreachable_server_says_what_to_check() {
    let Some(xvfb) = xvfb_or_skip("the unreachable server test") else {
        return;
    };
    // A port nobody listens on (bound, then released).
    let port = std::net::UdpSocket::bind("127.0.0.1:0")
        .unwrap()
        .local_addr()
        .unwrap()
        .port();
    let home = tempfile::tempdir().unwrap();
    let mut command = windowed(&xvfb, home.path());
    command
        .args(["--connect", &format!("127.0.0.1:{port}")])
        .args(["--cert-hash", &"ab".repeat(32)])
        .args(["--exit-after-ticks", "30", "--window", "320x240"]);
    let out = run_to_end(command, CLIENT_TIMEOUT);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(EXIT_FAILED), "{stderr}");
    let told = told(&out);
    assert_eq!(told.len(), 1, "told once: {stderr}");
    for needle in [
        format!("cannot join 127.0.0.1:{port}"),
        "address and port".to_owned(),
        "the server is running".to_owned(),
        "firewall".to_owned(),
    ] {
        assert!(told[0].contains(&needle), "{needle:?} missing: {}", told[0]);
    }
    assert!(!told[0].contains("connection failed: connection failed"));
}

#[test]
fn a_name_over_the_limit_is_a_command_line_error_naming_the_limit() {
    let long = "n".repeat(ledge_shared::protocol::MAX_NAME_LEN + 1);
    let mut command = Command::new(env!("CARGO_BIN_EXE_ledge-client"));
    command.args(["--connect", "127.0.0.1:1", "--name", &long]);
    let out = run_to_end(command, CLIENT_TIMEOUT);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(EXIT_USAGE), "{stderr}");
    assert!(stderr.contains("--name"), "{stderr}");
    assert!(
        stderr.contains(&format!(
            "at most {} bytes",
            ledge_shared::protocol::MAX_NAME_LEN
        )),
        "{stderr}"
    );
}

#[test]
fn help_lists_the_exit_codes() {
    let mut command = Command::new(env!("CARGO_BIN_EXE_ledge-client"));
    command.arg("--help");
    let out = run_to_end(command, CLIENT_TIMEOUT);
    assert!(out.status.success());
    let help = String::from_utf8_lossy(&out.stdout);
    let codes = help
        .split("Exit codes:")
        .nth(1)
        .expect("an exit codes section");
    for code in ["0  ", "1  ", "2  ", "3  "] {
        assert!(codes.contains(code), "{code:?} missing: {codes}");
    }
    assert!(codes.contains("--join-timeout") && codes.contains("certificate"));
}
