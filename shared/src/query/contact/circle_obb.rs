//! Contact between a circle and an oriented box.

use crate::shape::Obb;

super::circle_contact!(Obb);
