//! Contact between a point and a circle.

use crate::shape::Point;

// The circle kernel implements circle-against-point; this pair is its reverse.
super::circle_contact!(Point);
