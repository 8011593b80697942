//! Contact between a segment and a circle.

use crate::shape::Segment;

// The circle kernel implements circle-against-segment; this pair is its reverse.
super::circle_contact!(Segment);
