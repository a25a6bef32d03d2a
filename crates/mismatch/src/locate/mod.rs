//! Step 1, locate: the recording and the nominal model compared in the weak form, channel by
//! channel against a noise floor ([`problem`]), with the model's acceleration between the rows
//! ([`forward`]); the windows where they disagree are found by the analysis.

pub mod forward;
pub(crate) mod problem;
pub(crate) mod windows;
