//! Reports of the experiments: the paper's three tables and its qualitative figure.
//!
//! What it is for: the results types every tool reads and writes ([`ResultsTable`], whose JSON is
//! `{"table", "protocol", "rows": [{"condition", "sindy", "learn", "published", ...}]}`); rendering
//! them as Markdown ([`markdown`]), LaTeX in the paper's booktabs layout ([`latex`]) and JSON;
//! the paper's published numbers ([`PublishedTables`]); the regression check against them with
//! declared per-cell tolerances ([`Tolerances`], [`Comparison`]); and the paper's qualitative
//! figure as SVG ([`QualitativeFigure`]); learning curves as SVG and Markdown ([`CurveFigure`],
//! [`curve_markdown`]).
//!
//! What it is not for: computing any number. It knows nothing of flights, SINDy or LeARN: the
//! `pipeline` crate runs the experiments and hands the numbers and traces to this crate.
//!
//! The sim-to-real mismatch tool's outputs are rendered here too ([`mismatch`]: the Markdown, the
//! terminal text and the SVG figures of one recording, of several flights analysed together and
//! of the demo matrix), from plain result types and views that the `mismatch` crate fills.

mod compare;
mod curve;
mod error;
mod figure;
pub mod mismatch;
mod published;
mod render;
mod table;

pub use compare::{CellComparison, CellStatus, Comparison, Direction, ToleranceRule, Tolerances};
pub use curve::{CurveFigure, CurveSeries, curve_markdown};
pub use error::{ReportError, Result};
pub use figure::{
    ADAPTATION, Band, GENERALISATION, GROUND_TRUTH, MethodTrace, OutputAxis, QualitativeFigure,
};
pub use published::PublishedTables;
pub use render::{caption, latex, latex_label, markdown};
pub use table::{Method, MethodPair, Metric, Mse, PAPER_TABLES, ResultsTable, Row, load_tables};
