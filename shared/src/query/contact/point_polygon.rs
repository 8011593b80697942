//! Contact between a point and a convex polygon.

use crate::shape::{Point, ConvexPolygon};

super::sat_contact!(Point, ConvexPolygon);
