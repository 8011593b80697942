//! Contact between an axis-aligned box and an oriented box.

use crate::shape::{Aabb, Obb};

super::sat_contact!(Aabb, Obb);
