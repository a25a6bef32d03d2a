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
            Self::MotorCommands => columns(&log.motor_command),
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
    /// One over the median interval of the rows, Hz.
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

#[cfg(test)]
mod tests {
    use super::*;

    /// A 100 Hz log of `n` rows whose every signal is new at every row.
    fn fresh_log(n: usize) -> FlightLog {
        let wave = |k: usize, i: usize| (0.37 * k as f64 + i as f64).sin();
        FlightLog {
            path: "fresh.csv".into(),
            meta: None,
            time: (0..n).map(|k| k as f64 * 0.01).collect(),
            position: (0..n)
                .map(|k| std::array::from_fn(|i| wave(k, i)))
                .collect(),
            velocity: (0..n)
                .map(|k| std::array::from_fn(|i| wave(k, i + 3)))
                .collect(),
            quaternion: (0..n)
                .map(|k| {
                    let a = 0.1 * wave(k, 6);
                    [(0.5 * a).cos(), (0.5 * a).sin(), 0.0, 0.0]
                })
                .collect(),
            rotation: vec![[[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]; n],
            body_rate: (0..n)
                .map(|k| std::array::from_fn(|i| wave(k, i + 7)))
                .collect(),
            thrust_setpoint: vec![0.5; n],
            hover_throttle: vec![0.5; n],
            motor_command: (0..n)
                .map(|k| std::array::from_fn(|i| 1500.0 + 100.0 * wave(k, i + 10)))
                .collect(),
            battery_voltage: None,
            declared_rate_frame: None,
            position_desired: None,
            velocity_desired: None,
            attitude_setpoint: None,
            residual_force: None,
        }
    }

    #[test]
    fn a_log_fresh_at_every_row_has_nothing_to_say() {
        assert_eq!(measure(&fresh_log(200)), None);
    }

    /// Motor commands held for five rows of a 100 Hz log: the timing limit is their 50 ms, not the
    /// 0.4 s of a motor that barely moves.
    #[test]
    fn held_commands_set_the_timing_limit() {
        let n = 400;
        let mut log = fresh_log(n);
        for (k, u) in log.motor_command.iter_mut().enumerate() {
            let held = (k / 5) as f64;
            // The second motor barely moves: rounded, it changes every 40 rows only.
            let slow = 0.5 + 1e-3 * (k / 40) as f64;
            *u = [0.5 + 0.01 * held.sin(), slow, 0.5 + 0.01 * held.cos(), 0.5];
        }
        let content = measure(&log).expect("held commands");
        let commands = content
            .signals
            .iter()
            .find(|s| s.signal == Signal::MotorCommands)
            .unwrap();
        assert_eq!(commands.pattern, ColumnPattern::Held);
        let limit = content.timing_limit_s.unwrap();
        assert!((limit - 0.05).abs() < 0.001, "{limit}");
        assert!((content.row_rate_hz - 100.0).abs() < 1e-6);
    }
}
