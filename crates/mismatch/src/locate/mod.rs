//! Step 1, locate: the recording and the nominal model compared in the weak form, channel by
//! channel against a noise floor ([`problem`]), with the model's acceleration between the rows
//! ([`forward`]); whether the model's torques say anything about the recording at all
//! ([`response`]); the windows where they disagree are found by the analysis.

pub mod forward;
pub(crate) mod problem;
pub mod response;
pub(crate) mod windows;
