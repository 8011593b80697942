//! Contact between a point and an axis-aligned box.

use crate::shape::{Point, Aabb};

super::sat_contact!(Point, Aabb);
