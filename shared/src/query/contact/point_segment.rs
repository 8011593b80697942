//! Contact between a point and a segment.

use crate::shape::{Point, Segment};

super::sat_contact!(Point, Segment);
