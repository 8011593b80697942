//! Contact between an oriented box and a convex polygon.

use crate::shape::{Obb, ConvexPolygon};

super::sat_contact!(Obb, ConvexPolygon);
