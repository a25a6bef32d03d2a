//! The fits every step shares: effects' parameters fitted with the exact forward model
//! ([`refine`]), through the crate's one bounded Levenberg–Marquardt solver ([`least_squares`]),
//! and where in the recording a fit's estimates are read ([`weight`]).

pub mod least_squares;
pub(crate) mod refine;
pub mod weight;
