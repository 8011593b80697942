//! Contact between an axis-aligned box and a convex polygon.

use crate::shape::{Aabb, ConvexPolygon};

super::sat_contact!(Aabb, ConvexPolygon);
