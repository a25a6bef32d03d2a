//! Sim-to-real mismatch analysis for quadrotors.
//!
//! What it is for: given a recording and a nominal model, locate where they disagree (channels and
//! time windows, against a noise floor), name the missing physics from a library of candidate terms
//! (sparse selection that finds nothing on noise alone), fit the effects' parameters — nonlinear
//! ones included — and show the fit improve on a held-out part ([`analyze`]; its files: [`Analysis::render`]);
//! prove it on simulated recordings with concealed effects ([`demo`]) and run it on the real
//! Neural-Fly flights together ([`fleet`]).
//!
//! What it is not for: simulating (the `physics` crate), reading logs (the `data` crate), or
//! rendering its outputs: the Markdown, the terminal text and the SVG figures are rendered by the
//! `report` crate ([`report::mismatch`]) from views this crate fills ([`Analysis::view`] and
//! [`Analysis::figure`], [`fleet::FleetReport::view`], [`demo::DemoSummary::view`]); the plain
//! parts of the results (windows, channels, fit errors, every flight's air, the targets) are
//! `report`'s types, re-exported here; nor writing files or checking where they go: this crate
//! computes the results and renders each file's contents ([`Analysis::render`],
//! [`fleet::FleetReport::render`], [`demo::DemoSummary::render`]), and the caller (the `learn`
//! binary, through the `output_set` crate) checks the outputs and writes them.
//!
//! Method in one paragraph (the long version: `docs/mismatch.md`): the recording and the model are
//! compared in the weak form ([`weak_form`], from `sindy`: the recorded velocity and body rate against the model's
//! acceleration through the same smooth test function), the model's commands reconstructed as its
//! logger says ([`forward`]; instantaneous samples of a mixer's speeds through the per-rotor thrust,
//! runs at an actuator limit continued beyond it: [`command_samples`]); sampled commands of a faster
//! controller first lose their unfelt reaction to the logged noise ([`noise_reaction`]). Candidates are
//! screened by forward stepwise selection with blocked cross-validation and kept by stability
//! selection over block-bootstrap resamples; their parameters are fitted jointly with the exact model
//! on the first part of the recording (Levenberg–Marquardt, [`least_squares`], the solver of every
//! fit here); each effect is then named only when the evidence rule holds
//! for it ([`evidence`]), and the named effects' parameters are estimated again on all rows with
//! robust weights, each command step between samples with its time left free, and the bias the
//! sampled commands' noise leaves measured and removed ([`estimate`], [`simex`]). Several
//! flights of one vehicle are analysed together by [`fleet`].
//!
//! Names: every effect is named by a [`physics::EffectId`] (its spelling, `linear_drag` …, is what
//! the outputs print); the candidates of the library by a [`CandidateId`] (an effect, or the timing
//! term `delay_or_motor_lag`). Every choice that depends on an effect matches over those enums.

// Index loops over channels and 3-vectors read like the formulas they implement.
#![allow(clippy::needless_range_loop)]

// The method's steps, in order (each module's header says what it does).
mod analysis;
pub mod demo;
mod error;
pub mod explain;
pub mod fleet;
pub mod improve;
pub mod locate;
pub mod model;
pub mod recording;
mod settings;

pub use analysis::files::ANALYSIS_FILES;
pub use analysis::parts::{
    MIN_PART_ROWS, Part, PartedAnalysis, analyze_in_parts, check_part_rows, part_ranges,
};
pub use analysis::{
    Analysis, ChannelReport, EffectReport, Fit, RateFrame, Report, Stage, Window, analyze,
    analyze_observed,
};
pub use error::{MismatchError, Result};
pub use explain::describe::describe;
pub use explain::evidence::{Evidence, EvidenceSettings};
pub use explain::fit::FittedSet;
pub use explain::library::{Candidate, CandidateId, Term, build_library};
pub use locate::problem::{CHANNEL_NAMES, Channels, Problem};
pub use model::refine::{FitRows, effects_from, levenberg_marquardt};
pub use recording::Recording;
pub use settings::{
    AnalysisRecord, AnalysisSettings, CheckedSettings, ComparisonSettings, FleetRecord,
    FleetSettings, LocateSettings, NoiseFree, Settings,
};
pub use sindy::stability::{
    BlockDesign, Selection, SelectionSettings, stability_selection, stepwise, trimmed_gain,
};
pub use sindy::weak_form;
