//! What a log really holds: how often each signal the analysis reads brings a new value. A log
//! written at 100 Hz may carry motor commands that change at 10 Hz, held between updates or
//! interpolated between them (`data::ulog::NewSamples` tells which). What the analysis can
//! identify follows: a command's effect is seen only as often as the command changes, so a delay
//! or a motor lag shorter than the commands' effective interval cannot be identified from the log
//! (the analysis does not name one; [`LogContent::timing_limit_s`]).

use data::FlightLog;
use data::ulog::{ColumnPattern, NewSamples};
use serde::Serialize;

/// The signals of a recording whose content is measured.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Signal {
    Position,
    Velocity,
    Attitude,
    BodyRate,
    MotorCommands,
}

impl Signal {
    pub const ALL: [Signal; 5] = [
        Self::Position,
        Self::Velocity,
        Self::Attitude,
        Self::BodyRate,
        Self::MotorCommands,
    ];

    /// The signal as the report names it.
    pub const fn name(self) -> &'static str {
        match self {
            Self::Position => "position",
            Self::Velocity => "velocity",
            Self::Attitude => "attitude",
            Self::BodyRate => "body rate",
            Self::MotorCommands => "motor commands",
        }
    }

    /// Its components, per row.
    fn components(self, log: &FlightLog) -> Vec<Vec<f64>> {
        fn columns<const N: usize>(rows: &[[f64; N]]) -> Vec<Vec<f64>> {
            (0..N)
                .map(|i| rows.iter().map(|r| r[i]).collect())
                .collect()
        }
        match self {
            Self::Position => columns(&log.position),
            Self::Velocity => columns(&log.velocity),
            Self::Attitude => columns(&log.quaternion),
            Self::BodyRate => columns(&log.body_rate),
            Self::MotorCommands => (0..log.motor_command.count())
                .map(|i| log.motor_command.rows().map(|r| r[i]).collect())
                .collect(),
        }
    }
}

/// How often one signal brings a new value: that of its component that brings the most.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct SignalContent {
    pub signal: Signal,
    pub pattern: ColumnPattern,
    /// New values per second.
    pub effective_rate_hz: f64,
}

/// What a recording holds, signal by signal, when some signal is held or interpolated between
/// slower updates (absent from the report when every signal is new at every row).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct LogContent {
    /// Rows per second over the log (the mean rate), Hz.
    pub row_rate_hz: f64,
    pub signals: Vec<SignalContent>,
    /// The shortest delay or motor lag the log can resolve: the motor commands' effective
    /// interval, s, when they are held or interpolated.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub timing_limit_s: Option<f64>,
}

/// Precision the pattern test allows for (values stored as f32 in ULogs; text has at least that).
const PRECISION: f64 = f32::EPSILON as f64;

/// Measures what `log` holds; `None` when every signal is fresh at every row.
pub fn measure(log: &FlightLog) -> Option<LogContent> {
    let duration = log.time.last()? - log.time.first()?;
    if log.len() < 3 || duration <= 0.0 {
        return None;
    }
    let signals: Vec<SignalContent> = Signal::ALL
        .into_iter()
        .filter(|signal| *signal != Signal::Position || log.position_logged())
        .filter_map(|signal| content_of(signal, log, duration))
        .collect();
    if signals.iter().all(|s| s.pattern == ColumnPattern::Fresh) {
        return None;
    }
    let timing_limit_s = signals
        .iter()
        .find(|s| {
            s.signal == Signal::MotorCommands
                && matches!(s.pattern, ColumnPattern::Held | ColumnPattern::Interpolated)
        })
        .map(|s| 1.0 / s.effective_rate_hz);
    Some(LogContent {
        row_rate_hz: (log.len() - 1) as f64 / duration,
        signals,
        timing_limit_s,
    })
}

/// The content of the component of `signal` that brings the most new values (none when none
/// changes): a held signal repeats all its components together, while a slow component of a fresh
/// one (a yaw that barely moves, printed to a few digits) repeats by rounding alone.
fn content_of(signal: Signal, log: &FlightLog, duration: f64) -> Option<SignalContent> {
    signal
        .components(log)
        .iter()
        .map(|values| NewSamples::count(&log.time, values, PRECISION).pattern())
        .filter(|(pattern, new)| *pattern != ColumnPattern::Constant && *new > 0)
        .max_by_key(|(_, new)| *new)
        .map(|(pattern, new)| SignalContent {
            signal,
            pattern,
            effective_rate_hz: new as f64 / duration,
        })
}
