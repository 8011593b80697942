//! Serde helper for bounded lists (rosters, room lists, level lists): the list grows as entries arrive (never by
//! the claimed length) and one entry more than the bound is an error at
//! once, so a hostile count allocates nothing.

use std::marker::PhantomData;

use serde::de::{Deserialize, Error, SeqAccess, Visitor};
use serde::Deserializer;

struct Bounded<T> {
    max: usize,
    what: &'static str,
    item: PhantomData<T>,
}

impl<'de, T: Deserialize<'de>> Visitor<'de> for Bounded<T> {
    type Value = Vec<T>;
    fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
        write!(f, "at most {} {}", self.max, self.what)
    }
    fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<Self::Value, A::Error> {
        let mut v = Vec::new();
        while let Some(entry) = seq.next_element()? {
            if v.len() == self.max {
                return Err(A::Error::custom(format!(
                    "more than {} {}",
                    self.max, self.what
                )));
            }
            v.push(entry);
        }
        Ok(v)
    }
}

/// Deserializes a list of at most `max` entries (`what` names them in the
/// error), growing as entries arrive.
pub(super) fn seq<'de, D: Deserializer<'de>, T: Deserialize<'de>>(
    d: D,
    max: usize,
    what: &'static str,
) -> Result<Vec<T>, D::Error> {
    d.deserialize_seq(Bounded {
        max,
        what,
        item: PhantomData,
    })
}
