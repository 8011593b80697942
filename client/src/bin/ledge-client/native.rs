//! The native entry: the command line, the level file, the network
//! request (or an in-process server with `--local`), then the window.

use std::io::Write;
use std::path::PathBuf;
use std::sync::atomic::Ordering;
use std::time::Duration;

use clap::Parser;
use ledge_client::{Fingerprint, OnlineRequest, Trust};
use macroquad::prelude::vec2;

use crate::game_loop::{game, Setup};
use crate::input::keys::{self, Bindings};
use crate::input::script::Script;
use crate::outcome::{tell, EXIT_CODE, EXIT_FAILED, EXIT_UNTRUSTED};
use crate::{local, play, replay};

/// How long the window waits for the server's first answer before it
/// opens (showing "connecting..."): enough for the TLS handshake, so a
/// refused certificate is reported on the terminal without a window.
const CONNECT_WAIT: Duration = Duration::from_secs(3);

/// The exit codes, for `--help`.
const EXIT_CODES: &str = "Exit codes:
  0  the game ended normally (Esc, window closed, --exit-after-ticks reached);
     --replay --check: the replay played to its end as recorded
  1  the session failed (server unreachable, refused us or dropped us), or the
     game could not start (level or keys file, screenshot); a replay does not
     play (its level not found, it plays differently from the server); the
     reason is printed on stderr, prefixed \"ledge-client: \"
  2  a command-line error, or not joined within --join-timeout; the replay
     cannot be read (missing, damaged, cut short, newer, not on the server)
  3  the server's certificate was refused (wrong --cert-hash, or not the one
     remembered in the known-hosts file)

Replays (--replay FILE|URL): Space pause, -/+ (or [/]) speed 0.25x to 4x,
Left/Right 5 s back/forward, Home/End start/end, Tab next player (Shift+Tab
the one before), F free camera (WASD moves it), F1 debug, F2 HUD, M sound,
Esc quits.";

/// ledge: a networked 2D platformer.
///
/// Keys (rebind with --keys FILE; --print-keys shows the defaults): arrows
/// or WASD move, space, Z or K jump, down + jump drops through one-way
/// ledges, R restarts the run, M mutes, F1 debug overlay, F2 HUD on/off,
/// F3 network panel, G ghosts, C collision overlay, T or Enter chat, V the server's level list
/// (1-9 vote for the next level), Esc quits. Gamepads need
/// the `gamepad` build feature. Spectating (--spectate): Tab / Shift+Tab
/// the next player, F free camera (WASD moves it).
#[derive(Debug, Parser)]
#[command(version, after_help = EXIT_CODES)]
struct Cli {
    /// Server to join, as HOST:PORT (without it or --local: play offline).
    #[arg(long, value_name = "HOST:PORT")]
    connect: Option<String>,
    /// SHA-256 fingerprint of the server certificate (the server prints
    /// it): trust only that certificate. Without it, the certificate is
    /// trusted on first use and remembered in the known-hosts file.
    #[arg(long, value_name = "HEX", requires = "connect")]
    cert_hash: Option<Fingerprint>,
    /// Known-hosts file for trust on first use (one `HOST:PORT SHA256` line
    /// per server; created with its folder if missing) [default:
    /// $XDG_CONFIG_HOME/ledge/known_hosts or ~/.config/ledge/known_hosts].
    #[arg(
        long,
        value_name = "PATH",
        requires = "connect",
        conflicts_with = "cert_hash"
    )]
    known_hosts: Option<PathBuf>,
    /// Start a server in this process (127.0.0.1, any free port, the
    /// default level) and join it.
    #[arg(long, conflicts_with = "connect")]
    local: bool,
    /// Level file (OGMO `.json` or Tiled `.tmx`) to play offline; default:
    /// the embedded level. Online the server's level is downloaded (or
    /// found in the level cache); a file given here must be the server's.
    /// `--local` always plays the embedded level.
    #[arg(long, value_name = "FILE")]
    level: Option<PathBuf>,
    /// Where downloaded levels are kept [default:
    /// $XDG_CACHE_HOME/ledge/levels or ~/.cache/ledge/levels].
    #[arg(long, value_name = "DIR")]
    level_cache: Option<PathBuf>,
    /// The room to join (opened if the server has no room of that name
    /// and its room cap allows); default: the server picks.
    #[arg(long, value_name = "NAME", requires = "connect")]
    room: Option<String>,
    /// Watch the room rather than play: no body, the camera follows a
    /// player (Tab / Shift+Tab the next, F a free camera moved with WASD;
    /// --follow NAME picks whom first); takes no player's place.
    #[arg(long, requires = "connect")]
    spectate: bool,
    /// Print the server's rooms (name, level, players, capacity) and exit.
    #[arg(long, requires = "connect")]
    list_rooms: bool,
    /// The level's settings file for offline play [default: LEVEL.ledge.toml
    /// beside the level, when there is one; online, always that one, as the
    /// server's default].
    #[arg(long, value_name = "FILE")]
    level_settings: Option<PathBuf>,
    /// Player name: 1 to 32 bytes (UTF-8), no control characters.
    #[arg(long, default_value = "player", value_parser = parse_name)]
    name: String,
    /// Key bindings file (TOML; actions left out keep their defaults).
    #[arg(long, value_name = "FILE")]
    keys: Option<PathBuf>,
    /// Print the default key bindings file and exit.
    #[arg(long)]
    print_keys: bool,
    /// Scripted input instead of the keyboard: a file, or the script
    /// itself, e.g. "0-59 -> right; 60 -> right+jump" (ticks from the
    /// start of play -> buttons).
    #[arg(long, value_name = "FILE|SCRIPT")]
    script: Option<String>,
    /// Quit after this many ticks of play (from joining, or from the start
    /// offline).
    #[arg(long, value_name = "N")]
    exit_after_ticks: Option<u64>,
    /// Save a PNG of the frame at --exit-after-ticks, and PATH.json beside
    /// it (camera transform, our player's server position on screen).
    #[arg(long, value_name = "PATH", requires = "exit_after_ticks")]
    screenshot: Option<PathBuf>,
    /// Give up (exit code 2) when not joined within this many seconds (only
    /// with --exit-after-ticks; interactive sessions keep waiting).
    #[arg(long, value_name = "SECONDS", default_value_t = 20)]
    join_timeout: u64,
    /// Point the camera at world pixel X,Y instead of our player (for
    /// screenshots of any part of the level).
    #[arg(long, value_name = "X,Y", value_parser = parse_point)]
    look_at: Option<(f32, f32)>,
    /// Start with the debug overlay (F1) on.
    #[arg(long)]
    debug: bool,
    /// Start with the network panel and graph (F3) on.
    #[arg(long)]
    net: bool,
    /// Start with the collision overlay (C) on: what collides, entity
    /// boxes, spawns and a player's box at each, as `ledge-level render`
    /// draws them.
    #[arg(long)]
    collision: bool,
    /// Start with the whole HUD (F2) off: clean screenshots of the level.
    #[arg(long)]
    no_hud: bool,
    /// Sound volume, 0 to 100.
    #[arg(long, value_name = "0..=100", default_value_t = 80,
          value_parser = clap::value_parser!(u8).range(0..=100))]
    volume: u8,
    /// Start with sound muted (M toggles it).
    #[arg(long)]
    mute: bool,
    /// Play a replay: a file saved from a server, or its address on the
    /// server's web port, http://HOST:PORT/replays/ID. Its level is the
    /// embedded one, in the level cache, --level FILE, or downloaded from
    /// that server. Keys below.
    #[arg(long, value_name = "FILE|URL",
          conflicts_with_all = ["connect", "local", "script", "look_at"])]
    replay: Option<String>,
    /// With --replay: play it to its end as fast as possible, checking
    /// every state hash against the server's, without a window; print one
    /// line (or the reason it fails, exit code 1).
    #[arg(long, requires = "replay")]
    check: bool,
    /// With --replay: open it at this game tick (the HUD's "tick").
    #[arg(long, value_name = "TICK", requires = "replay")]
    replay_seek: Option<u64>,
    /// With --replay or --spectate: follow the player of this name (a
    /// run's replay follows its runner, a match's and a spectator its
    /// first player).
    #[arg(long, value_name = "NAME")]
    follow: Option<String>,
    /// With --replay: start at this speed (0.25, 0.5, 1, 2 or 4).
    #[arg(long, value_name = "X", requires = "replay")]
    replay_speed: Option<f32>,
    /// Window size, WIDTHxHEIGHT.
    #[arg(long, value_name = "WxH", default_value = "960x540", value_parser = parse_size)]
    window: (i32, i32),
}

fn parse_size(s: &str) -> Result<(i32, i32), String> {
    let (w, h) = s
        .split_once(['x', 'X'])
        .ok_or_else(|| "expected WIDTHxHEIGHT, e.g. 960x540".to_owned())?;
    let n = |v: &str| {
        v.trim()
            .parse::<i32>()
            .ok()
            .filter(|&v| (64..=16384).contains(&v))
            .ok_or_else(|| format!("'{v}': expected a size in pixels (64 to 16384)"))
    };
    Ok((n(w)?, n(h)?))
}

/// A player name the server accepts (checked here, so a bad one is a
/// command-line error naming the limit, not a refusal after connecting).
fn parse_name(s: &str) -> Result<String, String> {
    use ledge_shared::protocol::{check_name, MAX_NAME_LEN};
    if check_name(s).is_ok() {
        return Ok(s.to_owned());
    }
    Err(if s.is_empty() {
        "a player name cannot be empty".to_owned()
    } else if s.len() > MAX_NAME_LEN {
        format!(
            "the name is {} bytes long; a player name is at most {MAX_NAME_LEN} bytes",
            s.len()
        )
    } else {
        match check_name(s) {
            Err(ledge_shared::protocol::ProtocolError::InvalidString { problem, .. }) => {
                format!("the player name {problem}: use visible letters, digits and punctuation")
            }
            _ => "this player name is not allowed".to_owned(),
        }
    })
}

fn parse_point(s: &str) -> Result<(f32, f32), String> {
    let (x, y) = s
        .split_once(',')
        .ok_or_else(|| "expected X,Y, e.g. 400,240".to_owned())?;
    let n = |v: &str| {
        v.trim()
            .parse::<f32>()
            .ok()
            .filter(|v| v.is_finite())
            .ok_or_else(|| format!("'{v}': expected a number of pixels"))
    };
    Ok((n(x)?, n(y)?))
}

/// Runs the game from the command line; exits with the game's code.
pub fn main() {
    if let Err(e) = run() {
        tell(&format!("{e:#}"));
        std::process::exit(EXIT_FAILED);
    }
}

fn run() -> anyhow::Result<()> {
    // Parse before opening the window, so `--help` and errors need no display.
    let cli = Cli::parse();
    if cli.print_keys {
        print!("{}", keys::DEFAULT_KEYS);
        return Ok(());
    }
    tracing_subscriber::fmt()
        .with_env_filter(
            tracing_subscriber::EnvFilter::try_from_default_env().unwrap_or_else(|_| "info".into()),
        )
        .with_writer(std::io::stderr)
        .with_ansi(std::io::IsTerminal::is_terminal(&std::io::stderr()))
        // A closed stderr drops log lines instead of panicking.
        .log_internal_errors(false)
        .init();

    if cli.follow.is_some() && cli.replay.is_none() && !cli.spectate {
        use clap::CommandFactory;
        Cli::command()
            .error(
                clap::error::ErrorKind::MissingRequiredArgument,
                "--follow NAME needs --replay FILE|URL or --spectate",
            )
            .exit();
    }
    let bindings = match &cli.keys {
        Some(path) => Bindings::load(path).map_err(anyhow::Error::msg)?,
        None => Bindings::default(),
    };
    if let Some(replay) = cli.replay.clone() {
        return match replay::run(replay_args(cli, replay, bindings)) {
            0 => Ok(()),
            code => std::process::exit(code),
        };
    }
    let script = cli
        .script
        .as_deref()
        .map(Script::load)
        .transpose()
        .map_err(anyhow::Error::msg)?;
    // A level file's own art is drawn; the embedded level keeps ledge's
    // flat colours.
    let (level, level_art) = match &cli.level {
        Some(path) if !cli.local => {
            let loaded = ledge_levels::load_level(path, cli.level_settings.as_deref())
                .map_err(|e| anyhow::anyhow!("loading the level: {e}"))?;
            // What the importer ignored, guessed or placed: the player
            // (and the level's author) should see it.
            let mut err = std::io::stderr().lock();
            for w in &loaded.warnings {
                let _ = writeln!(err, "warning: {w}");
            }
            for w in &loaded.art.warnings {
                let _ = writeln!(err, "warning: level art: {w}");
            }
            let _ = writeln!(err, "ledge-client: {}", loaded_line(path, &loaded));
            (loaded.level, loaded.art)
        }
        _ => (ledge_levels::default_level(), Default::default()),
    };
    let mut server = None;
    let request = if cli.local {
        let s = local::LocalServer::start()?;
        let trust = Trust::Pinned(s.fingerprint);
        let request = OnlineRequest::new(&s.addr.to_string(), trust, &cli.name);
        server = Some(s);
        Some(request)
    } else {
        cli.connect.clone().map(|server| {
            let trust = Trust::from_args(cli.cert_hash, cli.known_hosts.clone());
            let default = OnlineRequest::new(&server, trust, &cli.name);
            OnlineRequest {
                level: cli.level.clone(),
                room: cli.room.clone(),
                spectate: cli.spectate,
                level_cache: cli.level_cache.clone().or(default.level_cache.clone()),
                ..default
            }
        })
    };
    if cli.list_rooms {
        if let Some(request) = &request {
            return list_rooms(request);
        }
    }
    let mut play = match request {
        Some(request) => {
            tracing::info!("connecting to {} ({})", request.server, request.trust);
            play::Play::online(request, level)?
        }
        None => play::Play::offline(level, &cli.name)?,
    };
    // A refused certificate ends here, on the terminal, before any window.
    play.wait_for_network(CONNECT_WAIT);
    if let Some(message) = play.untrusted() {
        tell(message);
        std::process::exit(EXIT_UNTRUSTED);
    }
    let setup = Setup {
        play,
        bindings,
        script,
        exit_after: cli.exit_after_ticks,
        screenshot: cli.screenshot,
        join_timeout: Duration::from_secs(cli.join_timeout),
        name: cli.name,
        debug: cli.debug,
        net: cli.net,
        collision: cli.collision,
        hud: !cli.no_hud,
        volume: f32::from(cli.volume) / 100.0,
        mute: cli.mute,
        look_at: cli.look_at.map(|(x, y)| vec2(x, y)),
        spectate: cli.spectate,
        follow: cli.follow.clone(),
        level_art,
        server,
    };

    let conf = macroquad::window::Conf {
        window_title: "ledge".to_owned(),
        window_width: cli.window.0,
        window_height: cli.window.1,
        window_resizable: true,
        ..Default::default()
    };
    // What `#[macroquad::main]` expands to, called directly so the command
    // line is parsed before a window exists.
    macroquad::Window::from_config(conf, game(setup));
    match EXIT_CODE.load(Ordering::Relaxed) {
        0 => Ok(()),
        code => std::process::exit(code),
    }
}

/// The level-load line: the level, its warnings, and when its collision
/// was guessed (the file says nothing about what collides) that it was.
fn loaded_line(path: &std::path::Path, loaded: &ledge_levels::LoadedLevel) -> String {
    let n = loaded.warnings.len() + loaded.art.warnings.len();
    let warnings = match n {
        0 => "no warnings".to_owned(),
        1 => "1 warning (above)".to_owned(),
        n => format!("{n} warnings (above)"),
    };
    let guessed = if ledge_levels::report::guessed_collision(loaded) {
        "; its collision is GUESSED: the file says nothing about what collides, so whole \
         layers were made solid (press C to see what collides; `ledge-level render` draws it)"
    } else {
        ""
    };
    format!(
        "level {:?} loaded from {}: {warnings}{guessed}",
        loaded.level.name,
        path.display()
    )
}

/// The replay's options from the command line.
fn replay_args(cli: Cli, replay: String, bindings: Bindings) -> replay::ReplayArgs {
    replay::ReplayArgs {
        replay,
        check: cli.check,
        seek: cli.replay_seek,
        follow: cli.follow,
        speed: cli.replay_speed,
        level: cli.level,
        level_settings: cli.level_settings,
        level_cache: cli.level_cache,
        bindings,
        exit_after: cli.exit_after_ticks,
        screenshot: cli.screenshot,
        debug: cli.debug,
        hud: !cli.no_hud,
        volume: f32::from(cli.volume) / 100.0,
        mute: cli.mute,
        window: cli.window,
    }
}

/// `--list-rooms`: prints the server's rooms, one line each.
fn list_rooms(request: &OnlineRequest) -> anyhow::Result<()> {
    let runtime = tokio::runtime::Builder::new_current_thread()
        .enable_all()
        .build()?;
    let (rooms, _) = runtime
        .block_on(ledge_client::list_rooms_trusted(
            &request.server,
            &request.trust,
        ))
        .map_err(|e| anyhow::anyhow!("cannot list the rooms of {}: {e}", request.server))?;
    let mut out = std::io::stdout().lock();
    let plural = if rooms.len() == 1 { "" } else { "s" };
    let _ = writeln!(out, "{} room{plural} on {}:", rooms.len(), request.server);
    for r in &rooms {
        let _ = writeln!(
            out,
            "  {}  level {}  {}/{} players",
            r.name, r.level_id, r.players, r.capacity
        );
    }
    let _ = writeln!(
        out,
        "join one with --room NAME (a new name opens a room while the server has places)"
    );
    Ok(())
}
