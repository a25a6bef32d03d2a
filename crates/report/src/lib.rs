//! Reports of the experiments: the paper's three tables and its qualitative figure, and every
//! text the runs write about their results.
//!
//! What it is for: the results types every tool reads and writes ([`ResultsTable`], whose JSON is
//! `{"table", "protocol", "rows": [{"condition", "sindy", "learn", "published", ...}]}`); rendering
//! them as Markdown ([`markdown`]), LaTeX in the paper's booktabs layout ([`latex`]) and JSON, and
//! the README's results block ([`readme_block`]); the note under a table on the query samples
//! outside the meta-training range ([`coverage_note`]); the ablation tables of `make ablations`
//! ([`ablations_markdown`] over [`AblationTables`], whose rows [`AblationRow`] are those of
//! `ablations.json`); the paper's published numbers ([`PublishedTables`]); the regression check
//! against them with declared per-cell tolerances ([`Tolerances`], [`Comparison`]); the paper's
//! qualitative figure as SVG ([`QualitativeFigure`]); learning curves as SVG and Markdown
//! ([`CurveFigure`], [`curve_markdown`]).
//!
//! What it is not for: computing any number. It knows nothing of flights, SINDy or LeARN and does
//! not depend on the crates that do: the `evaluation` crate runs the experiments and hands the
//! numbers and traces to this crate in its own plain types.
//!
//! The sim-to-real mismatch tool's outputs are rendered here too ([`mismatch`]: the Markdown, the
//! terminal text and the SVG figures of one recording, of several flights analysed together and
//! of the demo matrix), from plain result types and views that the `mismatch` crate fills.
//!
//! What `learn data inspect` says of a PX4 ULog is rendered here too ([`ulog_inspection`]), and of
//! a CSV flight log's time stamps ([`sample_timing`]), from the `data` crate's inspection as its
//! JSON hands it over.

mod ablations;
mod compare;
mod coverage;
mod curve;
mod error;
mod figure;
pub mod mismatch;
mod published;
mod render;
pub mod sample_timing;
mod table;
pub mod ulog_inspection;

pub use ablations::{
    AblationRow, AblationTables, Choice, NoiseFloor, SeedCell, VariantCell, VariantNote,
    ablations_markdown,
};
pub use compare::{CellComparison, CellStatus, Comparison, Direction, ToleranceRule, Tolerances};
pub use coverage::{FarthestInput, QueryCoverage, coverage_note};
pub use curve::{CurveFigure, CurveSeries, curve_markdown};
pub use error::{ReportError, Result};
pub use figure::{
    ADAPTATION, Band, GENERALISATION, GROUND_TRUTH, MethodTrace, OutputAxis, QualitativeFigure,
};
pub use published::PublishedTables;
pub use render::{caption, latex, latex_label, markdown, readme_block};
pub use table::{Method, MethodPair, Metric, Mse, PAPER_TABLES, ResultsTable, Row, load_tables};
