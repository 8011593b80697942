//! Contact between a point and an oriented box.

use crate::shape::{Point, Obb};

super::sat_contact!(Point, Obb);
