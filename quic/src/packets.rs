//! Fewer and smaller packets: acknowledgements that ride on the game's own
//! packets, and short connection ids.
//!
//! A game session is two steady streams of small datagrams: inputs up
//! (every tick or two) and snapshots down (every other tick). With QUIC's
//! default of an ACK for every second ack-eliciting packet, each end also
//! sends ACK-only packets (about one per snapshot on the server), each a
//! system call, an encryption and ~60 bytes on the wire for nothing the
//! game needs at once. Both ends ask the other, through the ACK frequency
//! extension (quinn implements its draft), to wait for up to
//! [`ACK_THRESHOLD`] packets or [`ACK_DELAY`] (quinn caps the delay at the
//! larger of the path's RTT and 25 ms), so an ACK goes out with the next
//! input or snapshot instead. Losses are still seen within a snapshot
//! interval or two: datagrams are never retransmitted, and the control
//! stream's retransmissions wait for at most that delay more.
//!
//! Every packet also carries its destination's connection id: 8 bytes by
//! default. The server's ids are [`SERVER_CID_LEN`] bytes (enough to tell a
//! few million connections apart; quinn re-draws a colliding one), and a
//! client endpoint that holds one connection uses none at all
//! ([`client_endpoint`]): packets to it are known by its socket.

use std::io;
use std::net::SocketAddr;
use std::time::Duration;

use quinn::{AckFrequencyConfig, Endpoint, EndpointConfig, ServerConfig, TransportConfig, VarInt};
use quinn_proto::RandomConnectionIdGenerator;

/// Ack-eliciting packets a peer may receive before it must send an ACK.
pub const ACK_THRESHOLD: u32 = 8;
/// The longest a peer should hold an ACK back (see the module docs).
pub const ACK_DELAY: Duration = Duration::from_millis(50);
/// Length of the server's connection ids, bytes.
pub const SERVER_CID_LEN: usize = 4;

/// Asks the peer to acknowledge at most every [`ACK_THRESHOLD`] packets or
/// [`ACK_DELAY`], so its ACKs ride on its own game packets.
pub fn ride_acks(transport: &mut TransportConfig) -> &mut TransportConfig {
    let mut acks = AckFrequencyConfig::default();
    acks.ack_eliciting_threshold(VarInt::from_u32(ACK_THRESHOLD))
        .max_ack_delay(Some(ACK_DELAY));
    transport.ack_frequency_config(Some(acks))
}

/// A server endpoint on `addr` serving `config`, with [`SERVER_CID_LEN`]-byte
/// connection ids (`quinn::Endpoint::server` with shorter ids).
pub fn server_endpoint(config: ServerConfig, addr: SocketAddr) -> io::Result<Endpoint> {
    endpoint(endpoint_config(SERVER_CID_LEN), Some(config), addr)
}

/// A client endpoint on `local` for one connection at a time, with
/// zero-length connection ids: the server's packets are known by the
/// server's address. An endpoint that connects to one server several times
/// at once needs ids: use `quinn::Endpoint::client` there.
pub fn client_endpoint(local: SocketAddr) -> io::Result<Endpoint> {
    endpoint(endpoint_config(0), None, local)
}

fn endpoint_config(cid_len: usize) -> EndpointConfig {
    let mut config = EndpointConfig::default();
    config.cid_generator(move || Box::new(RandomConnectionIdGenerator::new(cid_len)));
    config
}

fn endpoint(
    config: EndpointConfig,
    server: Option<ServerConfig>,
    addr: SocketAddr,
) -> io::Result<Endpoint> {
    let socket = std::net::UdpSocket::bind(addr)?;
    let runtime = quinn::default_runtime().ok_or_else(|| io::Error::other("no async runtime"))?;
    Endpoint::new(config, server, socket, runtime)
}
