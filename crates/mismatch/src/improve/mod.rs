//! Step 3, improve: the named effects' parameters estimated again on all rows with robust
//! weights ([`estimate`]), the bias the sampled commands' noise leaves removed ([`simex`]).

pub mod estimate;
pub mod simex;
