//! Replays for the replay tests: a match recorded on a level by bots
//! drilling (players joining and one leaving), written as files, played
//! headlessly to compare with the window, and a tiny HTTP server on
//! loopback answering as a ledge server's web port does
//! (`/replays/ID`, `/levels/HEX`).

use std::io::{Read, Write};
use std::net::{SocketAddr, TcpListener};
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use ledge_client::bot::brain::drill;
use ledge_shared::game::{Game, GameConfig};
use ledge_shared::input::Buttons;
use ledge_shared::level::Level;
use ledge_shared::protocol::{LevelOffer, PlayerId};
use ledge_shared::replay::{self, Playback, Replay, ReplayHeader, ReplayRecorder};

/// The players, by id from 1: ada and bob from the start, cy from tick
/// 400, dee from tick 800; bob leaves at tick 1800.
pub const NAMES: [&str; 4] = ["ada", "bob", "cy", "dee"];

/// A match being recorded, and its game.
pub struct Recording {
    pub game: Game,
    pub recorder: ReplayRecorder,
}

/// `ticks` ticks of a match on `level` (the bundle `offer` names), each
/// player drilling from an offset of its own.
pub fn record(level: &Level, offer: LevelOffer, ticks: u64) -> Recording {
    let header = ReplayHeader {
        recorded_at_ms: 1_790_000_000_000,
        ..ReplayHeader::for_match(
            "room-1",
            (&level.name, &level.name, offer),
            GameConfig::default(),
            60,
        )
    };
    let mut game = Game::from_level(level).expect("the level plays");
    let mut recorder = ReplayRecorder::new(header, &game);
    for _ in 0..ticks {
        let tick = game.tick();
        for (at, id) in [(0, 1), (0, 2), (400, 3), (800, 4)] {
            if tick == at {
                game.add_player(PlayerId(id)).expect("a player joins");
                recorder.join(PlayerId(id), NAMES[id as usize - 1]);
            }
        }
        if tick == 1800 && game.remove_player(PlayerId(2)) {
            recorder.leave(PlayerId(2));
        }
        let inputs: Vec<(PlayerId, Buttons)> = game
            .players()
            .map(|(id, _)| (id, drill(tick + 61 * u64::from(id.0))))
            .collect();
        game.step(&inputs);
        recorder.step(&game, &inputs);
    }
    Recording { game, recorder }
}

impl Recording {
    /// The whole match.
    pub fn replay(&self) -> Replay {
        self.recorder.replay(&self.game)
    }
}

/// `replay` as a file `name` in `dir`.
pub fn write(dir: &Path, name: &str, replay: &Replay) -> PathBuf {
    let path = dir.join(name);
    std::fs::write(&path, replay::encode(replay).expect("the replay encodes")).unwrap();
    path
}

/// `replay` played headlessly on `level` to game tick `tick`.
pub fn played_to(level: &Level, replay: Replay, tick: u64) -> Game {
    let mut playback = Playback::new(level, replay).expect("the replay plays");
    playback.seek(tick).expect("the replay plays to the tick");
    assert_eq!(playback.tick(), tick);
    playback.game().clone()
}

/// What the tiny web port answers for a path.
#[derive(Debug, Clone)]
pub enum Answer {
    /// 200 with these bytes (application/octet-stream).
    Bytes(Vec<u8>),
    /// 429 Too Many Requests with `Retry-After: N`.
    TooMany(u64),
    /// 200 announcing this Content-Length, sending a few bytes.
    Claims(u64),
}

/// A web port on loopback answering `routes` (path, answer; 404 for any
/// other path) until `requests` have been answered or 60 s passed.
pub fn serve(routes: Vec<(String, Answer)>, requests: usize) -> SocketAddr {
    let listener = TcpListener::bind("127.0.0.1:0").unwrap();
    let addr = listener.local_addr().unwrap();
    listener.set_nonblocking(true).unwrap();
    std::thread::spawn(move || {
        let deadline = Instant::now() + Duration::from_secs(60);
        let mut answered = 0;
        while answered < requests && Instant::now() < deadline {
            let Ok((mut stream, _)) = listener.accept() else {
                std::thread::sleep(Duration::from_millis(10));
                continue;
            };
            stream.set_nonblocking(false).unwrap();
            stream
                .set_read_timeout(Some(Duration::from_secs(5)))
                .unwrap();
            let mut request = Vec::new();
            let mut buf = [0u8; 1024];
            while !request.windows(4).any(|w| w == b"\r\n\r\n") && request.len() < 16_384 {
                match stream.read(&mut buf) {
                    Ok(0) | Err(_) => break,
                    Ok(n) => request.extend_from_slice(&buf[..n]),
                }
            }
            let text = String::from_utf8_lossy(&request);
            let path = text.split_whitespace().nth(1).unwrap_or("").to_owned();
            let answer = routes.iter().find(|(p, _)| *p == path).map(|(_, a)| a);
            let _ = match answer {
                Some(Answer::Bytes(body)) => respond(&mut stream, "200 OK", "", body, None),
                Some(Answer::TooMany(secs)) => respond(
                    &mut stream,
                    "429 Too Many Requests",
                    &format!("Retry-After: {secs}\r\n"),
                    b"too many requests",
                    None,
                ),
                Some(Answer::Claims(len)) => {
                    respond(&mut stream, "200 OK", "", b"LEDGEREP", Some(*len))
                }
                None => respond(&mut stream, "404 Not Found", "", b"not found", None),
            };
            answered += 1;
        }
    });
    addr
}

fn respond(
    stream: &mut std::net::TcpStream,
    status: &str,
    headers: &str,
    body: &[u8],
    claimed: Option<u64>,
) -> std::io::Result<()> {
    let len = claimed.unwrap_or(body.len() as u64);
    write!(
        stream,
        "HTTP/1.1 {status}\r\nContent-Type: application/octet-stream\r\nContent-Length: {len}\r\n\
         Connection: close\r\n{headers}\r\n"
    )?;
    stream.write_all(body)?;
    stream.flush()
}
