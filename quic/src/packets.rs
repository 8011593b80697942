//! Smaller packets: short connection ids.
//!
//! Every packet carries its destination's connection id: 8 bytes by
//! default. The server's ids are [`SERVER_CID_LEN`] bytes (enough to tell a
//! few million connections apart; quinn re-draws a colliding one), and a
//! client endpoint that holds one connection uses none at all
//! ([`client_endpoint`]): packets to it are known by its socket. At 30
//! packets a second each way that is 240 bytes a second down and 120 up
//! per player.
//!
//! Not used: QUIC's ACK frequency extension (quinn implements its draft),
//! which would let each end ask the other for fewer ACK-only packets. With
//! it, a second client joining through a link of 150 ms RTT, 25 ms jitter
//! and 5 % loss saw its hello time out on the server in each of three runs
//! (`tests/e2e/conditioned.rs`), and it is not needed: clients time their input
//! datagrams so that ACKs ride on the game's own packets
//! (`ledge_client::net::session::state`).

use std::io;
use std::net::SocketAddr;

use quinn::{Endpoint, EndpointConfig, ServerConfig};
use quinn_proto::RandomConnectionIdGenerator;

/// Length of the server's connection ids, bytes.
pub const SERVER_CID_LEN: usize = 4;

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
