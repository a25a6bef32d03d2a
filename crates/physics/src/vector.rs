//! The `rotation` crate's 3-vectors, 3×3 matrices and quaternions, under the name the simulator,
//! the effects and the mismatch analysis import them by. The maths is written once, there (shared
//! with the flight-log reader in `data`).

pub use rotation::*;
