//! Contact between a segment and a convex polygon.

use crate::shape::{Segment, ConvexPolygon};

super::sat_contact!(Segment, ConvexPolygon);
