//! Ray casts against every shape kind (first hit, distance, normal).
