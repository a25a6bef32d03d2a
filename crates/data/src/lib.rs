//! Flight data for learned-library system identification.
//!
//! What it is for: reading Neural-Fly flight logs into a typed, validated [`FlightLog`] (uniformly
//! sampled, or with [`Spacing::Any`] as a real logger spaces them: jitter, dropped rows, gaps;
//! [`SampleTiming`] says which); reading plain
//! numeric CSV and Parquet files by column name ([`NumericTable`], [`NumericStream`];
//! [`ColumnRef`] for `v[k]` of a CSV's list cells); several CSV
//! recordings of one system as the tasks of meta-learning ([`read_file_tasks`],
//! [`read_column_tasks`]); support/query splits ([`SplitSpec`]); the experiment's wind conditions
//! ([`ExperimentConditions`]); file hashes ([`file_sha256`]); finding the data directory
//! ([`resolve_data_dir`]); what a PX4 ULog holds for a flight analysis ([`ulog::inspect`]: rates,
//! jitter, gaps, the rate at which each key column really changes; the `ulog` crate reads it).
//!
//! What it is not for: fitting anything (models live in `sindy` and `learn`, tables in `report`),
//! nor the paper's protocol: a formulation's segments of a flight, the experiment and its
//! meta-training flights are the `evaluation` crate's.
//!
//! Every error is a [`DataError`] whose message is one line naming the file, and where it applies
//! the row (line number in the file, header = line 1; in a Parquet file the row counted from 1)
//! and column: `file:row:column: message`.

mod cells;
mod chunked;
mod columnar;
mod conditions;
mod error;
mod flight_log;
pub mod layout;
mod motors;
mod numeric;
mod pieces;
mod plain;
mod records;
mod source;
mod split;
mod stream;
mod table;
mod tasks;
mod time;
pub mod ulog;
mod write;

pub use columnar::{is_parquet, write_numeric_parquet};
pub use conditions::{Condition, ExperimentConditions, FlightFile, PaperTraining, Role};
pub use error::{DataError, Result};
pub use flight_log::{FlightLog, FlightMeta, REQUIRED_COLUMNS, RateFrame, SAMPLE_INTERVAL_RANGE_S};
pub use motors::{MAX_MOTORS, MotorCommands};
pub use numeric::NumericTable;
pub use records::LayoutFault;
pub use source::{
    DATA_DIR_VARIABLE, DEFAULT_DATA_DIR, bytes_sha256, file_sha256, find_data_dir,
    real_data_dir_for_tests, resolve_data_dir, shared_file_for_tests, ulog_file_for_tests,
};
pub use split::{Split, SplitSpec};
pub use stream::{NumericBlock, NumericStream, ReadAhead};
pub use table::ColumnRef;
pub use tasks::{MAX_TASKS, TaskTable, interval_text, read_column_tasks, read_file_tasks};
pub use time::{
    DEFAULT_UNIFORM_TOLERANCE, GAP_INTERVALS, SampleTiming, Spacing, StreamedTimeAxis,
    check_time_axis,
};
pub use write::write_numeric_csv;
