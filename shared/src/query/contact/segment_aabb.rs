//! Contact between a segment and an axis-aligned box.

use crate::shape::{Segment, Aabb};

super::sat_contact!(Segment, Aabb);
