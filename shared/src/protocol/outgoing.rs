//! Where an encoded snapshot goes: one datagram when it fits, else a
//! [`ServerControl::FullState`] frame on the control stream. Above both
//! the datagram and the control message, which it chooses between.

use super::codec::Message;
use super::control::ServerControl;
use super::datagram::Snapshot;
use super::frame::write_frame;
use super::ProtocolError;

/// Whether an encoded message of `len` bytes fits a datagram of at most
/// `max_datagram_size` bytes.
#[inline]
pub fn fits(len: usize, max_datagram_size: usize) -> bool {
    len <= max_datagram_size
}

/// An encoded snapshot and where to send it.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Outgoing {
    /// Send these bytes as one unreliable datagram.
    Datagram(Vec<u8>),
    /// Write these bytes (a complete frame, length prefix included) to the
    /// control stream.
    Control(Vec<u8>),
}

impl Snapshot {
    /// Encodes the snapshot for sending: as a datagram if it fits
    /// `max_datagram_size` (`quinn::Connection::max_datagram_size()`; `None`:
    /// datagrams unavailable), else as a framed
    /// [`ServerControl::FullState`] for the control stream.
    pub fn into_outgoing(
        self,
        max_datagram_size: Option<usize>,
    ) -> Result<Outgoing, ProtocolError> {
        let datagram = self.encode()?;
        if max_datagram_size.is_some_and(|max| fits(datagram.len(), max)) {
            return Ok(Outgoing::Datagram(datagram));
        }
        let mut frame = Vec::with_capacity(datagram.len() + 8);
        write_frame(&ServerControl::FullState(self), &mut frame)?;
        Ok(Outgoing::Control(frame))
    }
}
