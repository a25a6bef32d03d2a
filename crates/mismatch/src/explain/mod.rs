//! Step 2, explain: name the missing physics. Candidate terms from the effect registry
//! ([`library`]), their joint fit with the exact model ([`fit`]), the evidence rule that names an
//! effect only when it clearly beats the noise ([`evidence`]), and each effect's sentence
//! ([`describe`]).

pub(crate) mod describe;
pub mod evidence;
pub(crate) mod fit;
pub(crate) mod library;
