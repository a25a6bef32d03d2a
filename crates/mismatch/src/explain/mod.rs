//! Step 2, explain: name the missing physics. Candidate terms from the effect registry
//! ([`library`]), their joint fit with the exact model ([`fit`]), the evidence rule that names an
//! effect only when it clearly beats the noise ([`evidence`]), the test of each named effect
//! against the effects that could stand in for it on this recording ([`confounds`]), and each
//! effect's sentence ([`describe`]).

pub mod confounds;
pub(crate) mod describe;
pub mod evidence;
pub(crate) mod fit;
pub(crate) mod library;
