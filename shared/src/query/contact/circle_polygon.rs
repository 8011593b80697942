//! Contact between a circle and a convex polygon.

use crate::shape::ConvexPolygon;

super::circle_contact!(ConvexPolygon);
