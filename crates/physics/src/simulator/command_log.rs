//! What the simulated logger writes of the commands (each row's issued command, or their mean over
//! a log period) and the queue that delays the commands the plant receives.

use std::collections::VecDeque;

use data::FlightLog;

use crate::logger::CommandLogging;
use crate::mixer::{Actuators, MAX_ACTUATORS, Mixer};
use crate::model::NominalModel;
use crate::scenario::Scenario;

/// Motor speeds, collective thrust (N) and battery voltage (V; 0 without a battery) as logged.
type LoggedCommand = (Actuators, f64, f64);

/// The commands the logger writes: for each row, the issued commands it reads (one, or the mean
/// over a log period), found in a window of the most recent control steps.
pub(super) struct CommandLog {
    logging: CommandLogging,
    offset_steps: i64,
    per_row: usize,
    /// Recent control steps: (step, motor speeds, thrust, voltage).
    recent: VecDeque<(usize, LoggedCommand)>,
    /// Per row: its control step (from the first row) and, once known, its command.
    pub(super) rows: Vec<(usize, Option<LoggedCommand>)>,
    warmup_steps: usize,
    first: Option<LoggedCommand>,
    /// Rows before this one are filled (rows are filled in order).
    next: usize,
}

impl CommandLog {
    pub(super) fn new(scenario: &Scenario, rows: usize) -> Self {
        let logger = scenario.logger();
        let per_row = scenario.controller_steps_per_row();
        Self {
            logging: logger.command,
            offset_steps: (logger.command_time_offset_s * scenario.controller_rate()).round()
                as i64,
            per_row,
            recent: VecDeque::new(),
            rows: Vec::with_capacity(rows),
            warmup_steps: scenario.warmup_rows() * per_row,
            first: None,
            next: 0,
        }
    }

    /// The control steps a row recorded at `step` reads: `[low, high]`.
    fn span(&self, step: usize) -> (i64, i64) {
        let at = step as i64 + self.offset_steps;
        match self.logging {
            CommandLogging::Sample | CommandLogging::Held => (at, at),
            CommandLogging::PeriodMean => (at - self.per_row as i64, at - 1),
        }
    }

    pub(super) fn issue(&mut self, step: usize, command: LoggedCommand) {
        self.first.get_or_insert(command);
        self.recent.push_back((step, command));
        let keep = self.per_row + self.offset_steps.unsigned_abs() as usize + 2;
        while self.recent.len() > keep {
            self.recent.pop_front();
        }
    }

    pub(super) fn add_row(&mut self, step_from_first_row: usize) {
        self.rows.push((step_from_first_row, None));
    }

    /// Fills every pending row whose commands have all been issued by `step`.
    pub(super) fn fill_ready(&mut self, step: usize) {
        while self.next < self.rows.len() {
            let index = self.next;
            let row_step = self.rows[index].0 + self.warmup_steps;
            let (low, high) = self.span(row_step);
            if high > step as i64 {
                return;
            }
            self.next += 1;
            let first = self.first.expect("a command was issued");
            let mut sum = ([0.0; MAX_ACTUATORS], 0.0, 0.0);
            for wanted in low..=high {
                let (speeds, thrust, voltage) = self
                    .recent
                    .iter()
                    .find(|(s, _)| *s as i64 == wanted)
                    .map(|(_, command)| *command)
                    .unwrap_or(first);
                for i in 0..MAX_ACTUATORS {
                    sum.0[i] += speeds[i];
                }
                sum.1 += thrust;
                sum.2 += voltage;
            }
            let count = (high - low + 1) as f64;
            self.rows[index].1 = Some((sum.0.map(|v| v / count), sum.1 / count, sum.2 / count));
        }
    }

    /// Writes each row's commands into `log` (and its battery voltage, when it logs one).
    pub(super) fn write_into(
        self,
        log: &mut FlightLog,
        model: &NominalModel,
        mixer: &Mixer,
        hover_throttle: f64,
    ) {
        for (_, command) in self.rows {
            let (speeds, thrust, voltage) =
                command.expect("every row's command is issued by the last step");
            log.thrust_setpoint
                .push(thrust / (model.mass_kg * model.gravity_m_s2) * hover_throttle);
            log.hover_throttle.push(hover_throttle);
            let battery_v = log.battery_voltage.as_mut().map(|values| {
                values.push(voltage);
                voltage
            });
            log.motor_command.push(&mixer.commands(&speeds, battery_v));
        }
    }
}

/// The commands issued per physics step, of which only the last `delay_steps + 2` (and the very
/// first) are kept. A delay of `delay_steps + fraction` steps is exact: over each step the
/// actuators receive the command issued `delay_steps + 1` steps ago for its first `fraction`,
/// and the one issued `delay_steps` ago for the rest.
pub(super) struct CommandQueue {
    pub(super) delay_steps: usize,
    pub(super) fraction: f64,
    first: Option<Actuators>,
    pub(super) recent: VecDeque<Actuators>,
}

impl CommandQueue {
    /// A queue for a delay of `steps` physics steps (any non-negative number).
    pub(super) fn new(steps: f64) -> Self {
        // Within rounding of a whole number of steps, the delay is that number.
        let nearest = steps.round();
        let (whole, fraction) = if (steps - nearest).abs() < 1e-9 {
            (nearest, 0.0)
        } else {
            (steps.floor(), steps - steps.floor())
        };
        let delay_steps = whole as usize;
        Self {
            delay_steps,
            fraction,
            first: None,
            recent: VecDeque::with_capacity(delay_steps + 2),
        }
    }

    /// Records a command and returns the two the actuators receive over this step: the one
    /// issued `delay_steps + 1` physics steps ago (for the first `fraction` of it) and the one
    /// issued `delay_steps` ago (the first command before those).
    pub(super) fn push(&mut self, command: Actuators) -> (Actuators, Actuators) {
        let first = *self.first.get_or_insert(command);
        self.recent.push_back(command);
        if self.recent.len() > self.delay_steps + 2 {
            self.recent.pop_front();
        }
        let issued_ago = |steps: usize| {
            let len = self.recent.len();
            if len > steps {
                self.recent[len - 1 - steps]
            } else {
                first
            }
        };
        (
            issued_ago(self.delay_steps + 1),
            issued_ago(self.delay_steps),
        )
    }
}
