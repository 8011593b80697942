//! Contact between a segment and an oriented box.

use crate::shape::{Segment, Obb};

super::sat_contact!(Segment, Obb);
