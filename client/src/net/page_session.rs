//! The browser page's session: a session over a transport driven from
//! outside, sans IO: the browser's WebTransport or WebSocket (through the
//! page's glue), or anything else that carries the control stream's bytes,
//! datagrams and the level stream as messages.
//!
//! [`PageSession`] is the [`Network`] of a browser's
//! [`crate::net::online::OnlineGame`]: the driver calls
//! [`PageSession::on_open`] when the transport is up, feeds what arrives
//! ([`PageSession::on_message`], [`PageSession::on_closed`]), calls
//! [`PageSession::poll`] once per frame (pings) and sends what
//! [`PageSession::poll_transmit`] gives. Behind it are the same
//! [`Handshake`], [`SessionState`] and [`Download`] as the native client's,
//! so both speak one protocol. It reports as the background thread does:
//! the level ([`NetEvent::Level`], after its download if the server plays
//! another than the embedded one), then [`NetEvent::Connected`], then the
//! session's events; when the room moves to another level, that level
//! (downloaded by its SHA-256 the same way, the session's events waiting
//! meanwhile), then [`NetEvent::LevelChanged`].
//!
//! Everything queued here is bounded: at most [`MAX_EVENTS`] events and
//! [`MAX_TRANSMITS`] messages waiting (beyond, the oldest input datagrams,
//! then the oldest events, are dropped and counted).

use std::collections::{BTreeMap, VecDeque};
use std::time::Duration;

use ledge_shared::input::Buttons;
use ledge_shared::protocol::{
    write_frame, ClientControl, CloseCode, Message, NoticeKind, PlayerId, Welcome,
};

use crate::error::ClientError;
use crate::net::download::{embedded, level_change_failed, Download, Fetched};
use crate::net::session::{Handshake, JoinOptions, SessionEvent, SessionState};
use crate::net::{NetEvent, Network};
use crate::netstats::TransportSample;
use crate::time::Instant;

/// Something that arrived on the transport: the control stream's bytes,
/// a datagram, the level stream's bytes or its end (the kinds of the
/// WebSocket framing, whichever transport carried them).
pub use ledge_shared::protocol::web::WebMessage as Incoming;

/// Events waiting for the front end; beyond, the oldest are dropped.
pub const MAX_EVENTS: usize = 512;
/// Messages waiting for the transport; beyond, the oldest datagrams are
/// dropped (inputs repeat the last ticks: an old one is worthless).
pub const MAX_TRANSMITS: usize = 256;
/// How often the server is pinged (round-trip time).
pub const PING_EVERY: Duration = Duration::from_secs(1);
/// How long the server has to answer the hello.
pub const HELLO_TIMEOUT: Duration = crate::net::session::REPLY_TIMEOUT;

/// Something to send.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Transmit {
    /// Bytes to write on the control stream, in order.
    Stream(Vec<u8>),
    /// One datagram (an input packet).
    Datagram(Vec<u8>),
}

/// Where the session is.
#[derive(Debug)]
enum Phase {
    /// The transport is not up yet.
    Opening,
    /// Hello sent, waiting for the answer (since `.1`).
    Hello(Handshake, Instant),
    /// Welcomed; downloading the server's level first, if needed (and
    /// again whenever the room moves to another level: the session's
    /// events wait meanwhile).
    Joined {
        state: Box<SessionState>,
        download: Option<Download>,
        /// `Connected` was reported (the first level is there).
        connected: bool,
    },
    /// Over (the reason was reported).
    Ended,
}

/// The session's protocol over a driven transport (see the module).
#[derive(Debug)]
pub struct PageSession {
    options: JoinOptions,
    phase: Phase,
    events: VecDeque<NetEvent>,
    out: VecDeque<Transmit>,
    sample: TransportSample,
    last_ping: Option<Instant>,
    /// The server's last word before a close: a kick or its shutdown (a
    /// WebTransport close may reach a browser without its code).
    last_word: Option<(CloseCode, String)>,
    /// Messages or events dropped because a queue was full.
    dropped: u64,
    /// The welcome last reported (on joining or by a level change): a
    /// level change the join already had is not one.
    reported: Option<Welcome>,
}

impl PageSession {
    /// A session that will join as `options` say once its transport opens.
    pub fn new(options: JoinOptions) -> PageSession {
        PageSession {
            options,
            phase: Phase::Opening,
            events: VecDeque::new(),
            out: VecDeque::new(),
            sample: TransportSample::default(),
            last_ping: None,
            last_word: None,
            dropped: 0,
            reported: None,
        }
    }

    /// The transport is up: sends the hello (a name the server would
    /// refuse fails here, with the reason).
    pub fn on_open(&mut self, now: Instant) {
        if !matches!(self.phase, Phase::Opening) {
            return;
        }
        match Handshake::hello_frame(&self.options) {
            Ok(frame) => {
                self.transmit(Transmit::Stream(frame));
                self.phase = Phase::Hello(Handshake::new(), now);
            }
            Err(e) => self.fail(&e),
        }
    }

    /// Takes what arrived at `now`. A broken control stream or level
    /// download ends the session with the reason.
    pub fn on_message(&mut self, message: Incoming<'_>, now: Instant) {
        let len = match message {
            Incoming::Stream(b) | Incoming::Datagram(b) | Incoming::Level(b) => b.len(),
            Incoming::LevelEnd => 0,
        };
        self.sample.bytes_in += len as u64;
        let level = matches!(message, Incoming::Level(_) | Incoming::LevelEnd);
        let changing = self.changing_to().cloned();
        if let Err(e) = self.handle(message, now) {
            match changing {
                // The next level's download failed: say which level.
                Some(welcome) if level => {
                    self.end(NetEvent::Failed(level_change_failed(&welcome, &e)));
                }
                _ => self.fail(&e),
            }
        }
    }

    /// The level change's welcome while its level downloads.
    fn changing_to(&self) -> Option<&Welcome> {
        match &self.phase {
            Phase::Joined {
                state,
                download: Some(_),
                connected: true,
            } => Some(state.welcome()),
            _ => None,
        }
    }

    fn handle(&mut self, message: Incoming<'_>, now: Instant) -> Result<(), ClientError> {
        match (&mut self.phase, message) {
            (Phase::Hello(handshake, _), Incoming::Stream(bytes)) => {
                if let Some(state) = handshake.on_stream(bytes, now)? {
                    self.joined(state);
                }
            }
            (Phase::Joined { state, .. }, Incoming::Stream(bytes)) => {
                state.on_stream(bytes, now)?;
            }
            (Phase::Joined { state, .. }, Incoming::Datagram(bytes)) => {
                state.on_datagram(bytes, now);
            }
            (
                Phase::Joined {
                    download: Some(download),
                    ..
                },
                Incoming::Level(bytes),
            ) => {
                download.push(bytes)?;
                let (got, total) = download.progress();
                self.event(NetEvent::LevelProgress { got, total });
            }
            (Phase::Joined { download, .. }, Incoming::LevelEnd) if download.is_some() => {
                let (bundle, fetched) = download.take().expect("checked").finish()?;
                self.level_ready(bundle, fetched);
            }
            (_, Incoming::Level(_) | Incoming::LevelEnd) => {
                return Err(ClientError::Unexpected(
                    "a level stream nobody asked for".into(),
                ))
            }
            // Datagrams before the welcome (or after the end) mean nothing.
            (_, Incoming::Datagram(_)) | (Phase::Opening | Phase::Ended, Incoming::Stream(_)) => {}
        }
        self.drain_session();
        Ok(())
    }

    /// Welcomed: the level is the embedded one, or download it.
    fn joined(&mut self, state: SessionState) {
        let offer = state.welcome().level;
        let (download, ready) = if offer == embedded().1 {
            let fetched = Fetched {
                embedded: true,
                ..Fetched::default()
            };
            (None, Some((embedded().0.clone(), fetched)))
        } else {
            match Download::new(offer, Vec::new()) {
                Ok(download) => (Some(download), None),
                Err(e) => return self.fail(&e),
            }
        };
        if download.is_some() && !self.get_level(&offer) {
            return;
        }
        self.phase = Phase::Joined {
            state: Box::new(state),
            download,
            connected: false,
        };
        if let Some((bundle, fetched)) = ready {
            self.level_ready(bundle, fetched);
        }
    }

    /// Asks for the level `offer` names (by its SHA-256); `false` if the
    /// request could not be written (the session ended).
    fn get_level(&mut self, offer: &ledge_shared::protocol::LevelOffer) -> bool {
        let get = ClientControl::GetLevel {
            offset: 0,
            sha256: offer.sha256,
        };
        let mut frame = Vec::new();
        match write_frame(&get, &mut frame) {
            Ok(()) => {
                self.transmit(Transmit::Stream(frame));
                true
            }
            Err(e) => {
                self.fail(&e.into());
                false
            }
        }
    }

    /// The level is here: report it, then the welcome (on joining) or the
    /// level change.
    fn level_ready(&mut self, bundle: ledge_levels::LevelBundle, fetched: Fetched) {
        let Phase::Joined {
            state, connected, ..
        } = &mut self.phase
        else {
            return;
        };
        let changed = std::mem::replace(connected, true);
        let welcome = state.welcome().clone();
        self.reported = Some(welcome.clone());
        self.event(NetEvent::Level(Box::new(bundle), fetched));
        self.event(if changed {
            NetEvent::LevelChanged(Box::new(welcome))
        } else {
            NetEvent::Connected(welcome)
        });
    }

    /// The room moved to the session's latest welcome's level: the
    /// embedded one, or download it (the session's events wait).
    fn next_level(&mut self) {
        let Phase::Joined {
            state, download, ..
        } = &mut self.phase
        else {
            return;
        };
        let offer = state.welcome().level;
        if offer == embedded().1 {
            let fetched = Fetched {
                embedded: true,
                ..Fetched::default()
            };
            return self.level_ready(embedded().0.clone(), fetched);
        }
        match Download::new(offer, Vec::new()) {
            Ok(d) => *download = Some(d),
            Err(e) => {
                let message = level_change_failed(state.welcome(), &e);
                return self.end(NetEvent::Failed(message));
            }
        }
        if self.get_level(&offer) {
            self.event(NetEvent::LevelProgress {
                got: 0,
                total: offer.size,
            });
        }
    }

    /// Moves the session's events (once connected, and not while the next
    /// level downloads) to ours; a level change starts its level's
    /// download.
    fn drain_session(&mut self) {
        loop {
            let Phase::Joined {
                state,
                connected: true,
                download: None,
            } = &mut self.phase
            else {
                return;
            };
            let Some(event) = state.poll_event() else {
                return;
            };
            match &event {
                // The latest change only (another may be queued after).
                SessionEvent::LevelChange(w)
                    if w == state.welcome() && self.reported.as_ref() != Some(w) =>
                {
                    self.next_level();
                }
                SessionEvent::Pong { rtt: Some(rtt), .. } => self.sample.rtt = *rtt,
                SessionEvent::Notice(NoticeKind::Kick { reason }) => {
                    self.last_word = Some((CloseCode::Kicked, reason.clone()));
                }
                SessionEvent::Notice(NoticeKind::Shutdown) => {
                    self.last_word = Some((CloseCode::ServerShutdown, String::new()));
                }
                _ => {}
            }
            if let Some(event) = NetEvent::from_session(event) {
                self.event(event);
            }
        }
    }

    /// The transport closed with `code` (the server's [`CloseCode`] when it
    /// sent one) and `reason`. Without a code, the server's last notice (a
    /// kick, its shutdown) says why.
    pub fn on_closed(&mut self, code: Option<u32>, reason: &str) {
        let error = match code.and_then(CloseCode::from_u32) {
            Some(code) => ClientError::ClosedByServer {
                code: Some(code),
                reason: reason.to_owned(),
            },
            None if self.last_word.is_some() => {
                let (code, said) = self.last_word.clone().expect("checked");
                ClientError::ClosedByServer {
                    code: Some(code),
                    reason: said,
                }
            }
            None if reason.is_empty() => ClientError::StreamEnded,
            None => ClientError::Stream(reason.to_owned()),
        };
        self.fail(&error);
    }

    /// The transport failed (could not connect, or broke) with `reason`,
    /// in words.
    pub fn on_failed(&mut self, reason: &str) {
        self.fail(&ClientError::Stream(reason.to_owned()));
    }

    /// Ends the session with `error`: [`NetEvent::Disconnected`] once
    /// joined, [`NetEvent::Failed`] before. Only the first reason counts.
    fn fail(&mut self, error: &ClientError) {
        let event = match self.phase {
            Phase::Joined {
                connected: true, ..
            } => NetEvent::Disconnected(error.to_string()),
            _ => NetEvent::Failed(error.to_string()),
        };
        self.end(event);
    }

    /// Ends the session, reporting `event` (unless it had ended already).
    fn end(&mut self, event: NetEvent) {
        if matches!(
            std::mem::replace(&mut self.phase, Phase::Ended),
            Phase::Ended
        ) {
            return;
        }
        self.event(event);
    }

    /// Once per frame: pings the server every [`PING_EVERY`], and gives up
    /// on a server that has not answered the hello in [`HELLO_TIMEOUT`].
    pub fn poll(&mut self, now: Instant) {
        match &mut self.phase {
            Phase::Hello(_, since) if now.saturating_duration_since(*since) > HELLO_TIMEOUT => {
                self.fail(&ClientError::Timeout);
            }
            Phase::Joined { state, .. } => {
                let due = self
                    .last_ping
                    .is_none_or(|at| now.saturating_duration_since(at) >= PING_EVERY);
                if due {
                    self.last_ping = Some(now);
                    match state.ping_frame(now) {
                        Ok((_, frame)) => self.transmit(Transmit::Stream(frame)),
                        Err(e) => self.fail(&e),
                    }
                }
            }
            _ => {}
        }
    }

    /// The next message to send, oldest first.
    pub fn poll_transmit(&mut self) -> Option<Transmit> {
        self.out.pop_front()
    }

    /// Whether the session ended.
    pub fn is_ended(&self) -> bool {
        matches!(self.phase, Phase::Ended)
    }

    /// The welcome, once joined (the latest level change's, once the room
    /// moved on).
    pub fn welcome(&self) -> Option<&Welcome> {
        match &self.phase {
            Phase::Joined { state, .. } => Some(state.welcome()),
            _ => None,
        }
    }

    /// Messages and events dropped so far because a queue was full.
    pub fn dropped(&self) -> u64 {
        self.dropped
    }

    /// Queues a message; beyond [`MAX_TRANSMITS`] the oldest datagram (or
    /// else this one, if it is a datagram) is dropped. Control frames are
    /// never dropped: the stream would be out of step.
    fn transmit(&mut self, t: Transmit) {
        if self.out.len() >= MAX_TRANSMITS {
            match self
                .out
                .iter()
                .position(|t| matches!(t, Transmit::Datagram(_)))
            {
                Some(at) => {
                    self.out.remove(at);
                }
                None if matches!(t, Transmit::Datagram(_)) => {
                    self.dropped += 1;
                    return;
                }
                None => {}
            }
            self.dropped += 1;
        }
        let len = match &t {
            Transmit::Stream(b) | Transmit::Datagram(b) => b.len(),
        };
        self.sample.bytes_out += len as u64;
        self.out.push_back(t);
    }

    /// Queues an event; beyond [`MAX_EVENTS`] the oldest is dropped.
    fn event(&mut self, event: NetEvent) {
        if self.events.len() >= MAX_EVENTS {
            self.events.pop_front();
            self.dropped += 1;
        }
        self.events.push_back(event);
    }
}

impl Network for PageSession {
    fn try_recv(&mut self) -> Option<NetEvent> {
        self.events.pop_front()
    }

    fn send_input(&mut self, tick: u64, buttons: Buttons) -> bool {
        let Phase::Joined { state, .. } = &mut self.phase else {
            return false;
        };
        match state.input_datagram(tick, buttons) {
            Ok(Some(datagram)) => {
                self.transmit(Transmit::Datagram(datagram));
                true
            }
            Ok(None) => true,
            Err(_) => false,
        }
    }

    fn vote(&mut self, level: u32) -> bool {
        if !matches!(self.phase, Phase::Joined { .. }) {
            return false;
        }
        match SessionState::vote_frame(level) {
            Ok(frame) => {
                self.transmit(Transmit::Stream(frame));
                true
            }
            Err(_) => false,
        }
    }

    fn chat(&mut self, text: &str) -> bool {
        if !matches!(self.phase, Phase::Joined { .. }) {
            return false;
        }
        let message = ClientControl::Chat {
            text: text.to_owned(),
        };
        if message.validate().is_err() {
            return false;
        }
        let mut frame = Vec::new();
        if write_frame(&message, &mut frame).is_err() {
            return false;
        }
        self.transmit(Transmit::Stream(frame));
        true
    }

    fn transport(&self) -> Option<TransportSample> {
        matches!(self.phase, Phase::Joined { .. }).then_some(self.sample)
    }

    fn players(&self) -> BTreeMap<PlayerId, String> {
        match &self.phase {
            Phase::Joined { state, .. } => state.players().clone(),
            _ => BTreeMap::new(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use ledge_levels::LevelBundle;
    use ledge_shared::protocol::{
        FrameDecoder, InputPacket, NetTiming, RejectReason, RosterEntry, ServerControl, MAX_FRAME,
    };

    fn welcome(level: ledge_shared::protocol::LevelOffer) -> Welcome {
        Welcome {
            player_id: PlayerId(3),
            room: "friends".into(),
            level_id: "level".into(),
            level_hash: 0xabc,
            level,
            session_token: Default::default(),
            server_tick: 10,
            timing: NetTiming {
                tick_rate: 60,
                snapshot_interval: 2,
                input_redundancy: 4,
            },
            sim_config: vec![],
        }
    }

    fn frame(message: &ServerControl) -> Vec<u8> {
        let mut f = Vec::new();
        write_frame(message, &mut f).unwrap();
        f
    }

    /// The control messages among `out` (decoded), and the datagrams.
    fn sent(session: &mut PageSession) -> (Vec<ClientControl>, Vec<Vec<u8>>) {
        let mut decoder = FrameDecoder::new(MAX_FRAME);
        let mut datagrams = Vec::new();
        while let Some(t) = session.poll_transmit() {
            match t {
                Transmit::Stream(b) => decoder.push(&b).unwrap(),
                Transmit::Datagram(d) => datagrams.push(d),
            }
        }
        let mut controls = Vec::new();
        while let Some(m) = decoder.pop_message::<ClientControl>() {
            controls.push(m.unwrap());
        }
        (controls, datagrams)
    }

    fn events(session: &mut PageSession) -> Vec<NetEvent> {
        std::iter::from_fn(|| session.try_recv()).collect()
    }

    fn joining(room: &str) -> PageSession {
        PageSession::new(JoinOptions {
            room: Some(room.into()),
            ..JoinOptions::new("ada")
        })
    }

    #[test]
    fn joins_on_the_embedded_level_and_plays() {
        let now = Instant::now();
        let mut session = joining("friends");
        assert!(session.poll_transmit().is_none(), "nothing before the open");
        session.on_open(now);
        let (controls, _) = sent(&mut session);
        assert_eq!(
            controls[0].as_hello(),
            Some((
                ledge_shared::protocol::PROTOCOL_VERSION,
                "ada",
                Some("friends")
            ))
        );
        // The welcome and the roster in one read, split anywhere.
        let mut bytes = frame(&ServerControl::Welcome(welcome(embedded().1)));
        bytes.extend(frame(&ServerControl::Roster {
            players: vec![RosterEntry {
                id: PlayerId(3),
                name: "ada".into(),
            }],
        }));
        let (a, b) = bytes.split_at(7);
        session.on_message(Incoming::Stream(a), now);
        assert!(events(&mut session).is_empty());
        session.on_message(Incoming::Stream(b), now);
        let got = events(&mut session);
        assert!(
            matches!(&got[0], NetEvent::Level(_, f) if f.embedded),
            "{got:?}"
        );
        assert!(matches!(&got[1], NetEvent::Connected(w) if w.room == "friends"));
        assert!(
            matches!(&got[2], NetEvent::PlayerJoined { id: PlayerId(3), name } if name == "ada")
        );
        assert_eq!(session.players().len(), 1);

        // At 60 Hz a datagram goes every other tick, carrying the one
        // between.
        assert!(session.send_input(11, Buttons(Buttons::RIGHT)));
        assert!(session.send_input(12, Buttons(Buttons::JUMP)));
        assert!(session.send_input(13, Buttons(Buttons::RIGHT)));
        session.poll(now);
        let (controls, datagrams) = sent(&mut session);
        assert!(
            matches!(controls[..], [ClientControl::Ping { .. }]),
            "{controls:?}"
        );
        assert_eq!(datagrams.len(), 2, "ticks 11 and 13");
        assert_eq!(InputPacket::decode(&datagrams[0]).unwrap().newest_tick, 11);
        let packet = InputPacket::decode(&datagrams[1]).unwrap();
        assert_eq!(packet.newest_tick, 13);
        assert_eq!(packet.get(12), Some(Buttons(Buttons::JUMP)));
        assert_eq!(packet.get(11), Some(Buttons(Buttons::RIGHT)));
        assert!(session.transport().unwrap().bytes_out > 0);
    }

    #[test]
    fn downloads_another_level_before_reporting_the_welcome() {
        let now = Instant::now();
        let mut session = joining("friends");
        session.on_open(now);
        sent(&mut session);
        let mut bundle = LevelBundle::default_level();
        bundle.level.name = "another".into();
        let bytes = bundle.encode();
        let offer = LevelBundle::offer(&bytes);
        session.on_message(
            Incoming::Stream(&frame(&ServerControl::Welcome(welcome(offer)))),
            now,
        );
        let (controls, _) = sent(&mut session);
        assert!(
            matches!(controls[..], [ClientControl::GetLevel { offset: 0, sha256 }] if sha256 == offer.sha256),
            "{controls:?}"
        );
        // A roster while downloading waits for the welcome's report.
        session.on_message(
            Incoming::Stream(&frame(&ServerControl::PlayerLeft { id: PlayerId(9) })),
            now,
        );
        for chunk in bytes.chunks(4096) {
            session.on_message(Incoming::Level(chunk), now);
        }
        let progress = events(&mut session);
        assert!(progress
            .iter()
            .all(|e| matches!(e, NetEvent::LevelProgress { .. })));
        assert!(matches!(
            progress.last(),
            Some(NetEvent::LevelProgress { got, total }) if got == total
        ));
        session.on_message(Incoming::LevelEnd, now);
        let got = events(&mut session);
        assert!(
            matches!(&got[0], NetEvent::Level(b, f) if b.level.name == "another" && f.downloaded == bytes.len() as u64)
        );
        assert!(matches!(&got[1], NetEvent::Connected(_)));
        assert!(matches!(&got[2], NetEvent::PlayerLeft { id: PlayerId(9) }));
    }

    /// A session welcomed in "friends" on the embedded level (its events not
    /// taken).
    fn joined(now: Instant) -> PageSession {
        let mut session = joining("friends");
        session.on_open(now);
        session.on_message(
            Incoming::Stream(&frame(&ServerControl::Welcome(welcome(embedded().1)))),
            now,
        );
        session
    }

    /// A joined session that was just told it is kicked (events taken).
    fn kicked(now: Instant) -> PageSession {
        let mut session = joined(now);
        session.on_message(
            Incoming::Stream(&frame(&ServerControl::Notice {
                kind: NoticeKind::Kick {
                    reason: "sent too many datagrams".into(),
                },
            })),
            now,
        );
        events(&mut session);
        session
    }

    #[test]
    fn refusals_closes_and_silence_end_the_session_with_the_reason() {
        let now = Instant::now();
        let mut session = joining("friends");
        session.on_open(now);
        session.on_message(
            Incoming::Stream(&frame(&ServerControl::Reject {
                reason: RejectReason::RoomFull,
            })),
            now,
        );
        let got = events(&mut session);
        assert!(
            matches!(&got[..], [NetEvent::Failed(r)] if r.contains("room is full")),
            "{got:?}"
        );
        assert!(session.is_ended());
        session.on_closed(Some(CloseCode::Rejected.to_u32()), "full");
        assert!(
            events(&mut session).is_empty(),
            "only the first reason counts"
        );

        let mut session = joined(now);
        events(&mut session);
        session.on_closed(Some(CloseCode::Kicked.to_u32()), "flooding");
        let got = events(&mut session);
        assert!(
            matches!(&got[..], [NetEvent::Disconnected(r)] if r.contains("flooding")),
            "{got:?}"
        );

        // A close without a code (WebTransport in a browser) after a kick
        // notice: the notice says why.
        let mut session = kicked(now);
        session.on_failed("the WebTransport session broke");
        session.on_closed(None, "");
        let got = events(&mut session);
        assert!(
            matches!(&got[..], [NetEvent::Disconnected(r)] if r.contains("broke")),
            "a failure is a failure: {got:?}"
        );

        let mut session = kicked(now);
        session.on_closed(None, "");
        let got = events(&mut session);
        assert!(
            matches!(&got[..], [NetEvent::Disconnected(r)] if r.contains("removed us") && r.contains("too many datagrams")),
            "{got:?}"
        );

        let mut session = joining("friends");
        session.on_open(now);
        session.poll(now + HELLO_TIMEOUT + Duration::from_millis(1));
        let got = events(&mut session);
        assert!(
            matches!(&got[..], [NetEvent::Failed(r)] if r.contains("did not answer")),
            "{got:?}"
        );
    }

    #[test]
    fn a_level_stream_nobody_asked_for_is_an_error() {
        let now = Instant::now();
        let mut session = joined(now);
        events(&mut session);
        session.on_message(Incoming::Level(&[1, 2, 3]), now);
        assert!(matches!(
            &events(&mut session)[..],
            [NetEvent::Disconnected(_)]
        ));
    }

    /// Another level than the embedded one: its bundle's bytes and offer.
    fn another_level(name: &str) -> (LevelBundle, Vec<u8>, ledge_shared::protocol::LevelOffer) {
        let mut bundle = LevelBundle::default_level();
        bundle.level.name = name.into();
        let bytes = bundle.encode();
        let offer = LevelBundle::offer(&bytes);
        (bundle, bytes, offer)
    }

    /// An empty full snapshot of `tick`, as the control stream carries it.
    fn full_state(tick: u64) -> ServerControl {
        let state = ledge_shared::protocol::StateSnapshot {
            tick,
            ..Default::default()
        };
        let mut delta = Vec::new();
        ledge_shared::protocol::encode_delta(None, &state, &mut delta).unwrap();
        ServerControl::FullState(ledge_shared::protocol::Snapshot {
            tick,
            baseline_tick: None,
            last_input_tick: None,
            input_timing: 0,
            since_previous: 0,
            delta,
        })
    }

    #[test]
    fn a_level_change_downloads_the_new_level_by_its_hash_then_reports_it() {
        let now = Instant::now();
        let mut session = joined(now);
        events(&mut session);
        sent(&mut session);
        let (_, bytes, offer) = another_level("second");
        let mut next = welcome(offer);
        next.level_id = "second".into();
        next.server_tick = 500;
        // The change and the new level's first snapshot in one read.
        let mut read = frame(&ServerControl::LevelChange(next.clone()));
        read.extend(frame(&full_state(500)));
        session.on_message(Incoming::Stream(&read), now);
        let (controls, _) = sent(&mut session);
        assert!(
            matches!(controls[..], [ClientControl::GetLevel { offset: 0, sha256 }] if sha256 == offer.sha256),
            "{controls:?}"
        );
        assert_eq!(
            events(&mut session),
            [NetEvent::LevelProgress {
                got: 0,
                total: offer.size
            }],
            "the snapshot waits for the level"
        );
        assert_eq!(session.welcome().unwrap().level_id, "second");
        for chunk in bytes.chunks(4096) {
            session.on_message(Incoming::Level(chunk), now);
        }
        session.on_message(Incoming::LevelEnd, now);
        let got: Vec<NetEvent> = events(&mut session)
            .into_iter()
            .filter(|e| !matches!(e, NetEvent::LevelProgress { .. }))
            .collect();
        assert!(
            matches!(&got[..], [NetEvent::Level(b, _), NetEvent::LevelChanged(w), NetEvent::Snapshot(s)]
                if b.level.name == "second" && w.server_tick == 500 && s.state.tick == 500),
            "{got:?}"
        );
        // A vote goes on the control stream.
        assert!(session.vote(1));
        let (controls, _) = sent(&mut session);
        assert_eq!(controls, [ClientControl::Vote { level: 1 }]);
        // Back to the embedded level: nothing to download.
        let mut back = welcome(embedded().1);
        back.server_tick = 900;
        session.on_message(
            Incoming::Stream(&frame(&ServerControl::LevelChange(back))),
            now,
        );
        let got = events(&mut session);
        assert!(
            matches!(&got[..], [NetEvent::Level(_, f), NetEvent::LevelChanged(w)]
                if f.embedded && w.server_tick == 900),
            "{got:?}"
        );
        assert!(sent(&mut session).0.is_empty());
    }

    #[test]
    fn a_next_level_that_fails_to_download_ends_the_session_naming_it() {
        let now = Instant::now();
        let mut session = joined(now);
        events(&mut session);
        let (_, mut bytes, offer) = another_level("second");
        let mut next = welcome(offer);
        next.level_id = "second".into();
        session.on_message(
            Incoming::Stream(&frame(&ServerControl::LevelChange(next))),
            now,
        );
        bytes[3] ^= 0xff;
        session.on_message(Incoming::Level(&bytes), now);
        session.on_message(Incoming::LevelEnd, now);
        let got = events(&mut session);
        assert!(
            matches!(got.last(), Some(NetEvent::Failed(r)) if r.contains("\"second\"") && r.contains("does not match the hash")),
            "{got:?}"
        );
        assert!(session.is_ended());
    }

    #[test]
    fn queues_stay_bounded() {
        let now = Instant::now();
        let mut session = joined(now);
        for tick in 0..(MAX_TRANSMITS as u64 * 3) {
            session.send_input(tick, Buttons::NONE);
        }
        let (_, datagrams) = sent(&mut session);
        assert!(datagrams.len() <= MAX_TRANSMITS);
        assert!(session.dropped() > 0);
    }
}
