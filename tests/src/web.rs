//! Native clients of the server's browser transports, for the tests: a
//! WebSocket client ([`WsClient`], tokio-tungstenite) and a WebTransport
//! client ([`WtClient`], wtransport), both speaking the session exactly as
//! a browser page would, and [`http_get`] for the web port's documents.

use std::collections::VecDeque;
use std::net::{IpAddr, SocketAddr};
use std::time::Duration;

use futures_util::{SinkExt, StreamExt};
use ledge_shared::protocol::web::{self, Tag, WebMessage};
use ledge_shared::protocol::{
    write_frame, ClientControl, CloseCode, FrameDecoder, Message as _, ServerControl, MAX_FRAME,
};
use tokio::io::{AsyncReadExt, AsyncWriteExt};
use tokio::net::{TcpSocket, TcpStream};
use tokio_tungstenite::tungstenite::protocol::frame::coding::CloseCode as WsCloseCode;
use tokio_tungstenite::tungstenite::Message;
use tokio_tungstenite::WebSocketStream;
use wtransport::tls::Sha256Digest;

/// An HTTP answer.
#[derive(Debug, Clone)]
pub struct HttpAnswer {
    /// The status code.
    pub status: u16,
    /// The head (status line and headers), as text.
    pub head: String,
    /// The body.
    pub body: Vec<u8>,
}

impl HttpAnswer {
    /// The value of header `name` (case-insensitive), if present.
    pub fn header(&self, name: &str) -> Option<&str> {
        self.head.lines().skip(1).find_map(|line| {
            let (n, v) = line.split_once(':')?;
            n.trim().eq_ignore_ascii_case(name).then(|| v.trim())
        })
    }
}

/// A TCP connection to `addr` from `source` (another loopback address
/// stands for another machine), or from any address.
pub async fn connect_from(source: Option<IpAddr>, addr: SocketAddr) -> std::io::Result<TcpStream> {
    let Some(ip) = source else {
        return TcpStream::connect(addr).await;
    };
    let socket = match ip {
        IpAddr::V4(_) => TcpSocket::new_v4()?,
        IpAddr::V6(_) => TcpSocket::new_v6()?,
    };
    socket.bind(SocketAddr::new(ip, 0))?;
    socket.connect(addr).await
}

/// `GET path` over HTTP/1.1 on a fresh connection.
pub async fn http_get(addr: SocketAddr, path: &str) -> HttpAnswer {
    http_get_from(None, addr, path, &[])
        .await
        .expect("an answer")
}

/// `GET path` from `source` with `headers` (name, value) over HTTP/1.1 on
/// a fresh connection; `None` if the connection failed or no head came
/// within 10 s.
pub async fn http_get_from(
    source: Option<IpAddr>,
    addr: SocketAddr,
    path: &str,
    headers: &[(&str, &str)],
) -> Option<HttpAnswer> {
    let mut stream = connect_from(source, addr).await.ok()?;
    let extra: String = headers
        .iter()
        .map(|(n, v)| format!("{n}: {v}\r\n"))
        .collect();
    let request =
        format!("GET {path} HTTP/1.1\r\nHost: localhost\r\n{extra}Connection: close\r\n\r\n");
    stream.write_all(request.as_bytes()).await.ok()?;
    let mut response = Vec::new();
    tokio::time::timeout(Duration::from_secs(10), stream.read_to_end(&mut response))
        .await
        .ok()?
        .ok()?;
    parse_answer(&response)
}

/// An HTTP/1.1 answer's head and body (`None`: no head).
fn parse_answer(response: &[u8]) -> Option<HttpAnswer> {
    let split = response.windows(4).position(|w| w == b"\r\n\r\n")?;
    let head = String::from_utf8_lossy(&response[..split]).into_owned();
    let status = head.split_whitespace().nth(1)?.parse().ok()?;
    Some(HttpAnswer {
        status,
        head,
        body: response[split + 4..].to_vec(),
    })
}

/// What a web client received.
#[derive(Debug)]
pub enum WebEvent {
    /// A control message.
    Control(ServerControl),
    /// A datagram.
    Datagram(Vec<u8>),
    /// A whole level bundle download.
    Level(Vec<u8>),
    /// The server closed the session: the code (WebSocket: already mapped
    /// back from `4000 + code`; `None`: another code) and the reason.
    Closed(Option<CloseCode>, u32, String),
}

/// One frame of the control stream.
fn frame(message: &ClientControl) -> Vec<u8> {
    let mut frame = Vec::new();
    write_frame(message, &mut frame).expect("encodes");
    frame
}

/// A session over WebSocket (`/ws` on the web port).
pub struct WsClient {
    socket: WebSocketStream<TcpStream>,
    decoder: FrameDecoder,
    pending: VecDeque<WebEvent>,
    level: Vec<u8>,
}

/// Why a WebSocket connection failed.
#[derive(Debug)]
pub struct WsRefused {
    /// The HTTP status, when the server answered one.
    pub status: Option<u16>,
    /// The error.
    pub error: String,
}

impl WsClient {
    /// Connects to `ws://addr/ws`.
    pub async fn connect(addr: SocketAddr) -> Result<WsClient, WsRefused> {
        Self::connect_from(None, addr).await
    }

    /// Connects to `ws://addr/ws` from `source` ([`connect_from`]).
    pub async fn connect_from(
        source: Option<IpAddr>,
        addr: SocketAddr,
    ) -> Result<WsClient, WsRefused> {
        let stream = connect_from(source, addr).await.map_err(|e| WsRefused {
            status: None,
            error: e.to_string(),
        })?;
        let url = format!("ws://{addr}/ws");
        match tokio_tungstenite::client_async(url, stream).await {
            Ok((socket, _)) => Ok(WsClient {
                socket,
                decoder: FrameDecoder::new(MAX_FRAME + 16),
                pending: VecDeque::new(),
                level: Vec::new(),
            }),
            Err(tokio_tungstenite::tungstenite::Error::Http(response)) => Err(WsRefused {
                status: Some(response.status().as_u16()),
                error: format!("HTTP {}", response.status()),
            }),
            Err(e) => Err(WsRefused {
                status: None,
                error: e.to_string(),
            }),
        }
    }

    /// Sends a raw WebSocket message.
    pub async fn send_raw(&mut self, message: Message) -> bool {
        self.socket.send(message).await.is_ok()
    }

    /// Sends a control message (one `Stream` message, split in two to show
    /// that any slice of the stream will do).
    pub async fn send_control(&mut self, message: &ClientControl) {
        let frame = frame(message);
        let (a, b) = frame.split_at(frame.len() / 2);
        for part in [a, b] {
            let m = Message::Binary(web::encode(Tag::Stream, part));
            self.socket.send(m).await.expect("sends");
        }
    }

    /// Sends a datagram.
    pub async fn send_datagram(&mut self, datagram: &[u8]) -> bool {
        let m = Message::Binary(web::encode(Tag::Datagram, datagram));
        self.socket.send(m).await.is_ok()
    }

    /// The next event, or `None` after `within`.
    pub async fn next(&mut self, within: Duration) -> Option<WebEvent> {
        tokio::time::timeout(within, self.next_event()).await.ok()
    }

    async fn next_event(&mut self) -> WebEvent {
        loop {
            if let Some(e) = self.pending.pop_front() {
                return e;
            }
            let message = match self.socket.next().await {
                Some(Ok(m)) => m,
                Some(Err(e)) => return WebEvent::Closed(None, 0, e.to_string()),
                None => return WebEvent::Closed(None, 0, "ended".into()),
            };
            match message {
                Message::Binary(bytes) => match web::decode(&bytes).expect("well-formed") {
                    WebMessage::Stream(bytes) => {
                        self.decoder.push(bytes).expect("well-framed");
                        while let Some(payload) = self.decoder.pop() {
                            let control = ServerControl::decode(&payload).expect("decodes");
                            self.pending.push_back(WebEvent::Control(control));
                        }
                    }
                    WebMessage::Datagram(d) => return WebEvent::Datagram(d.to_vec()),
                    WebMessage::Level(chunk) => self.level.extend_from_slice(chunk),
                    WebMessage::LevelEnd => {
                        return WebEvent::Level(std::mem::take(&mut self.level))
                    }
                },
                Message::Close(frame) => {
                    let (code, reason) = frame
                        .map(|f| (u16::from(f.code), f.reason.into_owned()))
                        .unwrap_or((u16::from(WsCloseCode::Status), String::new()));
                    return WebEvent::Closed(web::from_close_code(code), code.into(), reason);
                }
                Message::Text(t) => panic!("a text message from the server: {t}"),
                _ => {}
            }
        }
    }
}

/// A session over WebTransport (`https://addr/ledge`).
pub struct WtClient {
    /// The client endpoint (kept open with the session).
    pub endpoint: wtransport::Endpoint<wtransport::endpoint::endpoint_side::Client>,
    /// The session.
    pub connection: wtransport::Connection,
    send: wtransport::SendStream,
    recv: wtransport::RecvStream,
    decoder: FrameDecoder,
    pending: VecDeque<WebEvent>,
    stream_ended: bool,
}

impl WtClient {
    /// Connects to `https://addr{path}` trusting only certificates whose
    /// SHA-256 is in `hashes` (as a browser's `serverCertificateHashes`),
    /// and opens the control stream.
    pub async fn connect(
        addr: SocketAddr,
        path: &str,
        hashes: &[[u8; 32]],
    ) -> Result<WtClient, String> {
        let config = wtransport::ClientConfig::builder()
            .with_bind_default()
            .with_server_certificate_hashes(hashes.iter().map(|h| Sha256Digest::new(*h)))
            .build();
        let endpoint = wtransport::Endpoint::client(config).map_err(|e| e.to_string())?;
        let url = format!("https://{addr}{path}");
        let connection = endpoint.connect(url).await.map_err(|e| e.to_string())?;
        let (send, recv) = connection
            .open_bi()
            .await
            .map_err(|e| e.to_string())?
            .await
            .map_err(|e| e.to_string())?;
        Ok(WtClient {
            endpoint,
            connection,
            send,
            recv,
            decoder: FrameDecoder::new(MAX_FRAME + 16),
            pending: VecDeque::new(),
            stream_ended: false,
        })
    }

    /// SHA-256 of the certificate the server presented.
    pub fn server_cert_sha256(&self) -> [u8; 32] {
        let chain = self.connection.peer_identity().expect("a certificate");
        *chain.as_slice()[0].hash().as_ref()
    }

    /// Sends a control message.
    pub async fn send_control(&mut self, message: &ClientControl) {
        self.send.write_all(&frame(message)).await.expect("sends");
    }

    /// Sends a datagram.
    pub fn send_datagram(&self, datagram: &[u8]) -> bool {
        self.connection.send_datagram(datagram).is_ok()
    }

    /// The next event, or `None` after `within`.
    pub async fn next(&mut self, within: Duration) -> Option<WebEvent> {
        tokio::time::timeout(within, self.next_event()).await.ok()
    }

    async fn next_event(&mut self) -> WebEvent {
        let mut buf = vec![0u8; 4096];
        loop {
            if let Some(e) = self.pending.pop_front() {
                return e;
            }
            tokio::select! {
                read = self.recv.read(&mut buf), if !self.stream_ended => match read {
                    Ok(Some(n)) => {
                        self.decoder.push(&buf[..n]).expect("well-framed");
                        while let Some(payload) = self.decoder.pop() {
                            let control = ServerControl::decode(&payload).expect("decodes");
                            self.pending.push_back(WebEvent::Control(control));
                        }
                    }
                    // The server finished the stream: the close follows.
                    Ok(None) => self.stream_ended = true,
                    Err(_) => return self.closed().await,
                },
                datagram = self.connection.receive_datagram() => match datagram {
                    Ok(d) => return WebEvent::Datagram(d.payload().to_vec()),
                    Err(_) => return self.closed().await,
                },
                uni = self.connection.accept_uni() => match uni {
                    Ok(mut stream) => {
                        let mut level = Vec::new();
                        let mut chunk = vec![0u8; 16 * 1024];
                        while let Ok(Some(n)) = stream.read(&mut chunk).await {
                            level.extend_from_slice(&chunk[..n]);
                        }
                        return WebEvent::Level(level);
                    }
                    Err(_) => return self.closed().await,
                },
            }
        }
    }

    async fn closed(&self) -> WebEvent {
        match self.connection.closed().await {
            wtransport::error::ConnectionError::ApplicationClosed(close) => {
                let code = close.code().into_inner();
                let reason = String::from_utf8_lossy(close.reason()).into_owned();
                let code32 = u32::try_from(code).unwrap_or(u32::MAX);
                WebEvent::Closed(CloseCode::from_u32(code32), code32, reason)
            }
            e => WebEvent::Closed(None, 0, e.to_string()),
        }
    }
}
