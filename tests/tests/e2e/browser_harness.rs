//! The headless Chromium harness (`ledge_tests::browser`) itself: a page
//! served over plain HTTP on loopback gets WebGL, real key events and a
//! kept console; screenshots show what WebGL drew; WebTransport can be
//! switched off; dropping the browser leaves no process and no profile.
//!
//! Without `chromium` on PATH these tests print a loud SKIPPED notice and
//! pass, except with `CI=true`, where they fail.

use std::io::{Read, Write};
use std::net::TcpListener;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use ledge_tests::browser::{skip_without_chromium, Browser, ConsoleMessage, Key, Options, Page};
use serde_json::json;

/// The colour the page's WebGL clears its canvas to, every frame.
const CANVAS_RGB: [u8; 3] = [32, 160, 96];
/// The canvas's place on the page (CSS pixels).
const CANVAS_LEFT: u32 = 100;
const CANVAS_TOP: u32 = 60;
const CANVAS_WIDTH: u32 = 320;
const CANVAS_HEIGHT: u32 = 180;

const PAGE: &str = r#"<!doctype html>
<html><head><meta charset="utf-8"><title>harness</title>
<style>html, body { margin: 0; background: #000; }
canvas { position: absolute; left: 100px; top: 60px; }</style></head>
<body><canvas id="c" width="320" height="180"></canvas>
<script>
window.keys = []; window.codes = []; window.keyCodes = []; window.ups = [];
window.addEventListener("keydown", (e) => {
  keys.push(e.key); codes.push(e.code); keyCodes.push(e.keyCode);
});
document.addEventListener("keyup", (e) => ups.push(e.code));
const gl = document.getElementById("c").getContext("webgl");
window.hasWebGL = gl !== null;
window.frames = 0;
function frame() {
  gl.clearColor(32 / 255, 160 / 255, 96 / 255, 1);
  gl.clear(gl.COLOR_BUFFER_BIT);
  window.frames += 1;
  requestAnimationFrame(frame);
}
if (gl) requestAnimationFrame(frame);
console.log("harness page ready", 42, { webgl: window.hasWebGL });
console.warn("a warning");
</script></body></html>
"#;

/// Serves `html` at `/` (404 elsewhere) over HTTP/1.0 on 127.0.0.1 from a
/// background thread; returns the page's URL.
fn serve(html: &'static str) -> String {
    let listener = TcpListener::bind("127.0.0.1:0").expect("binds a loopback port");
    let addr = listener.local_addr().unwrap();
    std::thread::spawn(move || {
        for stream in listener.incoming() {
            let Ok(mut stream) = stream else { continue };
            let mut request = Vec::new();
            let mut buf = [0u8; 1024];
            while !request.windows(4).any(|w| w == b"\r\n\r\n") {
                match stream.read(&mut buf) {
                    Ok(0) | Err(_) => break,
                    Ok(n) => request.extend_from_slice(&buf[..n]),
                }
            }
            let request = String::from_utf8_lossy(&request);
            let path = request.split_whitespace().nth(1).unwrap_or("");
            let (status, body) = if path == "/" {
                ("200 OK", html)
            } else {
                ("404 Not Found", "not found")
            };
            let _ = write!(
                stream,
                "HTTP/1.0 {status}\r\nContent-Type: text/html; charset=utf-8\r\n\
                 Content-Length: {}\r\nConnection: close\r\n\r\n{body}",
                body.len()
            );
        }
    });
    format!("http://{addr}/")
}

fn launch(options: Options) -> Browser {
    Browser::launch_with(options).unwrap_or_else(|e| panic!("launching Chromium: {e:#}"))
}

fn open(browser: &Browser, url: &str) -> Page {
    let mut page = browser.new_page().unwrap_or_else(|e| {
        panic!(
            "new page: {e:#}\nChromium's stderr:\n{}",
            browser.stderr_tail()
        )
    });
    page.open(url)
        .unwrap_or_else(|e| panic!("opening {url}: {e:#}"));
    page
}

/// Polls the console until a message satisfies `wanted` (or 20 s pass).
fn console_until(page: &mut Page, wanted: impl Fn(&ConsoleMessage) -> bool) -> bool {
    let deadline = Instant::now() + Duration::from_secs(20);
    while Instant::now() < deadline {
        if page.console().iter().any(&wanted) {
            return true;
        }
        std::thread::sleep(Duration::from_millis(50));
    }
    false
}

/// An RGB(A) screenshot, decoded.
struct Picture {
    width: u32,
    height: u32,
    samples: usize,
    pixels: Vec<u8>,
}

impl Picture {
    fn decode(png_bytes: &[u8]) -> Picture {
        let mut decoder = png::Decoder::new(png_bytes);
        decoder.set_transformations(png::Transformations::EXPAND | png::Transformations::STRIP_16);
        let mut reader = decoder.read_info().expect("the screenshot is a PNG");
        let mut pixels = vec![0; reader.output_buffer_size()];
        let info = reader.next_frame(&mut pixels).expect("the PNG decodes");
        let samples = match info.color_type {
            png::ColorType::Rgb => 3,
            png::ColorType::Rgba => 4,
            other => panic!("screenshot colour type {other:?}, expected RGB(A)"),
        };
        pixels.truncate(info.buffer_size());
        Picture {
            width: info.width,
            height: info.height,
            samples,
            pixels,
        }
    }

    fn rgb(&self, x: u32, y: u32) -> [u8; 3] {
        let at = (y as usize * self.width as usize + x as usize) * self.samples;
        [self.pixels[at], self.pixels[at + 1], self.pixels[at + 2]]
    }
}

fn close(a: [u8; 3], b: [u8; 3]) -> bool {
    a.iter().zip(b).all(|(&x, y)| x.abs_diff(y) <= 3)
}

#[test]
fn a_page_gets_webgl_real_keys_and_a_kept_console() {
    if skip_without_chromium("a_page_gets_webgl_real_keys_and_a_kept_console") {
        return;
    }
    let url = serve(PAGE);
    let browser = launch(Options::default());
    let mut page = open(&browser, &url);

    // WebGL without a GPU, drawing frames.
    let webgl = page.eval("window.hasWebGL").expect("evaluates");
    assert_eq!(
        webgl,
        json!(true),
        "no WebGL context; console:\n{}",
        page.console_text()
    );
    page.wait_until("window.frames >= 3", Duration::from_secs(30))
        .unwrap_or_else(|e| panic!("{e:#}"));

    // The screenshot has the window's size and shows the canvas's colour
    // inside it and the page's black around it.
    let shot = Picture::decode(&page.screenshot_png().expect("screenshot"));
    assert_eq!((shot.width, shot.height), (960, 540), "screenshot size");
    let inside = [
        (
            CANVAS_LEFT + CANVAS_WIDTH / 2,
            CANVAS_TOP + CANVAS_HEIGHT / 2,
        ),
        (CANVAS_LEFT + 1, CANVAS_TOP + 1),
        (
            CANVAS_LEFT + CANVAS_WIDTH - 2,
            CANVAS_TOP + CANVAS_HEIGHT - 2,
        ),
    ];
    for (x, y) in inside {
        assert!(
            close(shot.rgb(x, y), CANVAS_RGB),
            "pixel ({x}, {y}) inside the canvas is {:?}, expected {CANVAS_RGB:?}",
            shot.rgb(x, y)
        );
    }
    let outside = [
        (CANVAS_LEFT - 2, CANVAS_TOP + 10),
        (CANVAS_LEFT + CANVAS_WIDTH + 1, CANVAS_TOP + 10),
        (CANVAS_LEFT + 10, CANVAS_TOP + CANVAS_HEIGHT + 1),
        (900, 500),
    ];
    for (x, y) in outside {
        assert!(
            close(shot.rgb(x, y), [0, 0, 0]),
            "pixel ({x}, {y}) outside the canvas is {:?}, expected black",
            shot.rgb(x, y)
        );
    }

    // Real key events reach window and document listeners.
    page.press(Key::ArrowRight).expect("presses ArrowRight");
    page.press(Key::Space).expect("presses Space");
    page.wait_until("window.ups.length >= 2", Duration::from_secs(10))
        .unwrap_or_else(|e| panic!("{e:#}"));
    assert_eq!(
        page.eval("window.keys").unwrap(),
        json!(["ArrowRight", " "])
    );
    assert_eq!(
        page.eval("window.codes").unwrap(),
        json!(["ArrowRight", "Space"])
    );
    assert_eq!(page.eval("window.keyCodes").unwrap(), json!([39, 32]));
    assert_eq!(
        page.eval("window.ups").unwrap(),
        json!(["ArrowRight", "Space"])
    );

    // Held keys: down without up, then up.
    page.key_down(Key::Letter('z')).expect("holds Z");
    page.key_down(Key::ArrowLeft).expect("holds ArrowLeft");
    page.wait_until("window.keys.length >= 4", Duration::from_secs(10))
        .unwrap_or_else(|e| panic!("{e:#}"));
    assert_eq!(
        page.eval("window.codes.slice(2)").unwrap(),
        json!(["KeyZ", "ArrowLeft"])
    );
    assert_eq!(
        page.eval("window.ups.length").unwrap(),
        json!(2),
        "nothing released yet"
    );
    page.key_up(Key::ArrowLeft).expect("releases ArrowLeft");
    page.key_up(Key::Letter('z')).expect("releases Z");
    for key in [Key::ArrowUp, Key::ArrowDown, Key::Escape] {
        page.press(key).expect("presses");
    }
    page.wait_until("window.ups.length >= 7", Duration::from_secs(10))
        .unwrap_or_else(|e| panic!("{e:#}"));
    assert_eq!(
        page.eval("window.ups.slice(2)").unwrap(),
        json!(["ArrowLeft", "KeyZ", "ArrowUp", "ArrowDown", "Escape"])
    );
    assert!(
        page.press(Key::Letter('1')).is_err(),
        "only letters are letters"
    );

    // The console: the page's own messages, then an uncaught exception and
    // an unhandled rejection; a throwing eval is an error that says why.
    let messages: Vec<String> = page.console().iter().map(|m| m.to_string()).collect();
    assert!(
        messages
            .iter()
            .any(|m| m.starts_with("[log] harness page ready 42 ")),
        "console.log missing: {messages:#?}"
    );
    assert!(
        messages.contains(&"[warning] a warning".to_owned()),
        "console.warn missing: {messages:#?}"
    );
    page.eval("setTimeout(() => { throw new Error('deliberate failure'); }, 0); 1")
        .expect("evaluates");
    page.eval("Promise.reject(new Error('deliberate rejection')); 1")
        .expect("evaluates");
    assert!(
        console_until(&mut page, |m| m.kind == "exception"
            && m.text.contains("deliberate failure")),
        "uncaught exception missing: {}",
        page.console_text()
    );
    assert!(
        console_until(&mut page, |m| m.kind == "exception"
            && m.text.contains("deliberate rejection")),
        "unhandled rejection missing: {}",
        page.console_text()
    );
    let error = page.eval("null.x").expect_err("throws");
    assert!(format!("{error:#}").contains("TypeError"), "{error:#}");
    assert_eq!(
        page.eval("new Promise((r) => setTimeout(() => r([1, 'two']), 10))")
            .unwrap(),
        json!([1, "two"]),
        "promises are awaited"
    );
}

#[test]
fn webtransport_can_be_switched_off() {
    if skip_without_chromium("webtransport_can_be_switched_off") {
        return;
    }
    let url = serve(PAGE);
    for (webtransport, expected) in [(false, "undefined"), (true, "function")] {
        let browser = launch(Options {
            webtransport,
            ..Options::default()
        });
        let mut page = open(&browser, &url);
        // The page is a secure context (loopback over plain HTTP), so
        // WebTransport's absence comes from the option.
        assert_eq!(page.eval("window.isSecureContext").unwrap(), json!(true));
        for load in ["first load", "after a reload"] {
            assert_eq!(
                page.eval("typeof WebTransport").unwrap(),
                json!(expected),
                "webtransport: {webtransport}, {load}"
            );
            page.open(&url).expect("reloads");
        }
        // A second tab too.
        let mut other = open(&browser, &url);
        assert_eq!(other.eval("typeof WebTransport").unwrap(), json!(expected));
        assert_eq!(other.eval("typeof WebSocket").unwrap(), json!("function"));
    }
}

/// Processes (not zombies) in process group `pgid`.
fn group_members(pgid: u32) -> Vec<u32> {
    let mut members = Vec::new();
    for entry in std::fs::read_dir("/proc").expect("/proc") {
        let entry = entry.unwrap();
        let Some(pid) = entry
            .file_name()
            .to_str()
            .and_then(|n| n.parse::<u32>().ok())
        else {
            continue;
        };
        let Ok(stat) = std::fs::read_to_string(entry.path().join("stat")) else {
            continue;
        };
        // pid (comm) state ppid pgrp ...
        let Some(rest) = stat.rsplit_once(')').map(|(_, rest)| rest) else {
            continue;
        };
        let fields: Vec<&str> = rest.split_whitespace().collect();
        if fields.len() > 2 && fields[0] != "Z" && fields[2] == pgid.to_string() {
            members.push(pid);
        }
    }
    members
}

#[test]
fn dropping_the_browser_kills_chromium_and_removes_its_profile() {
    if skip_without_chromium("dropping_the_browser_kills_chromium_and_removes_its_profile") {
        return;
    }
    let browser = launch(Options::default());
    let mut page = open(&browser, "about:blank");
    assert_eq!(page.eval("1 + 1").unwrap(), json!(2));
    let pid = browser.pid();
    let profile: PathBuf = browser.profile_dir().to_owned();
    assert!(profile.is_dir(), "profile {profile:?} exists while running");
    assert!(
        group_members(pid).len() > 1,
        "Chromium runs helper processes in its group"
    );
    drop(browser);
    assert!(
        !Path::new(&format!("/proc/{pid}")).exists(),
        "Chromium {pid} reaped"
    );
    assert!(!profile.exists(), "profile {profile:?} removed");
    let deadline = Instant::now() + Duration::from_secs(20);
    while !group_members(pid).is_empty() && Instant::now() < deadline {
        std::thread::sleep(Duration::from_millis(50));
    }
    assert_eq!(
        group_members(pid),
        Vec::<u32>::new(),
        "Chromium's helpers are gone"
    );
    assert!(page.eval("1").is_err(), "a page of a dropped browser fails");
}

#[test]
fn a_missing_chromium_says_how_to_install_it() {
    let error = Browser::launch_with(Options {
        executable: Some("/nonexistent/chromium".into()),
        ..Options::default()
    })
    .expect_err("no such executable");
    let message = format!("{error:#}");
    assert!(message.contains("apt-get install -y chromium"), "{message}");
}
