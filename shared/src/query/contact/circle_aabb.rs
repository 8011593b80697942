//! Contact between a circle and an axis-aligned box.

use crate::shape::Aabb;

super::circle_contact!(Aabb);
