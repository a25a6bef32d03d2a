//! PX4 ULog flight logs (read by the `ulog` crate): what a log holds for a flight analysis
//! ([`inspect`]: vehicle, duration, airborne time, and per topic its rates, time-stamp jitter,
//! gaps and the rate at which each key column really changes) and its parameters as plain numbers
//! ([`parameter_table`]); chosen columns of several topics on one clock ([`aligned_table`], and
//! from a CSV export of the log, one file per topic, [`aligned_export_table`]); a
//! flight log written as PX4 logs it ([`flight_log_as_ulog`]).

mod aligned;
mod csv_export;
mod export;
mod inspect;
mod parameters;
mod rates;

pub use aligned::{AlignedTable, HeldColumn, aligned_table};
pub use csv_export::aligned_export_table;
pub use export::{START_TIME_US, flight_log_as_ulog};
pub use inspect::{
    Airborne, ColumnRate, DropoutSummary, Gaps, RatesOver, SLOW_COMMAND_RATE_HZ, StepSpread,
    TimingLimit, TopicInspection, UlogInspection, VehicleInfo, inspect,
};
pub use parameters::{ParameterTable, parameter_table};
pub use rates::{ColumnPattern, NewSamples, column_pattern};
