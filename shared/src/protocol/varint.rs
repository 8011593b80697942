//! LEB128 varints and zig-zag signed mapping, for the hand-written snapshot
//! delta format.
//!
//! Unsigned values are written 7 bits per byte, least significant group
//! first, the high bit of each byte set when more follow. The reader accepts
//! only the canonical (shortest) form and rejects values that overflow the
//! requested width, so every accepted byte string has exactly one meaning and
//! re-encodes to itself.

use super::ProtocolError;

/// Maps a signed value to an unsigned one so small magnitudes stay small:
/// 0, -1, 1, -2, 2 ... become 0, 1, 2, 3, 4 ...
#[inline]
pub fn zigzag32(v: i32) -> u32 {
    ((v << 1) ^ (v >> 31)) as u32
}

/// Inverse of [`zigzag32`].
#[inline]
pub fn unzigzag32(u: u32) -> i32 {
    ((u >> 1) as i32) ^ -((u & 1) as i32)
}

/// Appends `v` as a varint (1 to 10 bytes).
#[inline]
pub fn put_u64(out: &mut Vec<u8>, mut v: u64) {
    while v >= 0x80 {
        out.push((v as u8) | 0x80);
        v >>= 7;
    }
    out.push(v as u8);
}

/// Appends `v` as a varint (1 to 5 bytes).
#[inline]
pub fn put_u32(out: &mut Vec<u8>, v: u32) {
    put_u64(out, v as u64)
}

/// A cursor over bytes being decoded; every read is bounds-checked.
pub struct Reader<'a> {
    bytes: &'a [u8],
    pos: usize,
    what: &'static str,
}

impl<'a> Reader<'a> {
    /// Reads `bytes`; errors name `what`.
    pub fn new(bytes: &'a [u8], what: &'static str) -> Self {
        Reader {
            bytes,
            pos: 0,
            what,
        }
    }

    /// Bytes not read yet.
    #[inline]
    pub fn remaining(&self) -> usize {
        self.bytes.len() - self.pos
    }

    /// A malformed-input error about this structure.
    pub fn error(&self, detail: &'static str) -> ProtocolError {
        ProtocolError::malformed(self.what, format!("{detail} (at byte {})", self.pos))
    }

    /// Reads one byte.
    #[inline]
    pub fn u8(&mut self) -> Result<u8, ProtocolError> {
        let b = *self
            .bytes
            .get(self.pos)
            .ok_or_else(|| self.error("unexpected end"))?;
        self.pos += 1;
        Ok(b)
    }

    /// Reads a canonical varint of at most `bits` significant bits.
    fn varint(&mut self, bits: u32) -> Result<u64, ProtocolError> {
        let mut value = 0u64;
        let mut shift = 0u32;
        loop {
            let b = self.u8()?;
            let group = (b & 0x7f) as u64;
            if shift >= bits || (shift > 0 && bits - shift < 7 && group >> (bits - shift) != 0) {
                return Err(self.error("varint overflows its type"));
            }
            value |= group << shift;
            if b & 0x80 == 0 {
                if b == 0 && shift > 0 {
                    return Err(self.error("varint is not in its shortest form"));
                }
                return Ok(value);
            }
            shift += 7;
        }
    }

    /// Reads a varint that must fit `u64`.
    #[inline]
    pub fn u64(&mut self) -> Result<u64, ProtocolError> {
        self.varint(64)
    }

    /// Reads a varint that must fit `u32`.
    #[inline]
    pub fn u32(&mut self) -> Result<u32, ProtocolError> {
        self.varint(32).map(|v| v as u32)
    }

    /// Fails unless every byte was read.
    pub fn finish(&self) -> Result<(), ProtocolError> {
        match self.remaining() {
            0 => Ok(()),
            extra => Err(ProtocolError::TrailingBytes {
                what: self.what,
                extra,
            }),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_trips_and_rejects_non_canonical() {
        for v in [
            0u64,
            1,
            127,
            128,
            300,
            u32::MAX as u64,
            u64::MAX - 1,
            u64::MAX,
        ] {
            let mut out = Vec::new();
            put_u64(&mut out, v);
            let mut r = Reader::new(&out, "test");
            assert_eq!(r.u64().unwrap(), v);
            r.finish().unwrap();
        }
        // 0 written in two bytes.
        assert!(Reader::new(&[0x80, 0x00], "t").u64().is_err());
        // 2^32 does not fit u32.
        assert!(Reader::new(&[0x80, 0x80, 0x80, 0x80, 0x10], "t")
            .u32()
            .is_err());
        assert_eq!(
            Reader::new(&[0xff, 0xff, 0xff, 0xff, 0x0f], "t")
                .u32()
                .unwrap(),
            u32::MAX
        );
        // 11 bytes / 2^64.
        assert!(Reader::new(&[0xff; 11], "t").u64().is_err());
        assert!(Reader::new(
            &[0x80, 0x80, 0x80, 0x80, 0x80, 0x80, 0x80, 0x80, 0x80, 0x02],
            "t"
        )
        .u64()
        .is_err());
        for v in [0, 1, -1, i32::MAX, i32::MIN, 12345, -12345] {
            assert_eq!(unzigzag32(zigzag32(v)), v);
        }
        assert_eq!(zigzag32(-1), 1);
        assert_eq!(zigzag32(1), 2);
    }
}
