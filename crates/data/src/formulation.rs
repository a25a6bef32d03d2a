//! The paper's three formulations as data: which state is identified, from which inputs.
//!
//! | formulation | state x (I) | control u (U) | target |
//! |---|---|---|---|
//! | `Translational` | v (3) | R·[0, 0, T], T = raw `T_sp` (3) | v̇ |
//! | `Attitude` | ω (3) | motor speeds nᵢ = pwmᵢ/1000 (4) | ω̇ |
//! | `Full` | [v; ω] (6) | squared speeds nᵢ² = (pwmᵢ/1000)² (4) | [v̇; ω̇] |
//!
//! These scalings (thrust as the normalised setpoint, not newtons; pwm divided by 1000) are the ones
//! that reproduce the paper's SINDy columns. The learned models see X = [x, u] in that order.

use std::ops::Range;

use faer::Mat;
use serde::{Deserialize, Serialize};

use crate::error::{DataError, Result};
use crate::flight_log::FlightLog;
use sindy::Derivative;

/// Which part of the quadrotor dynamics is identified.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Formulation {
    Translational,
    Attitude,
    Full,
}

const VELOCITY: [&str; 3] = ["v_x", "v_y", "v_z"];
const RATE: [&str; 3] = ["w_x", "w_y", "w_z"];
const THRUST_VECTOR: [&str; 3] = ["u_x", "u_y", "u_z"];
const MOTOR_SPEED: [&str; 4] = ["n_1", "n_2", "n_3", "n_4"];
const MOTOR_SPEED_SQUARED: [&str; 4] = ["n_1_sq", "n_2_sq", "n_3_sq", "n_4_sq"];

impl Formulation {
    /// The three formulations in the paper's order.
    pub const ALL: [Formulation; 3] = [Self::Translational, Self::Attitude, Self::Full];

    /// The lower-case name used in files and on the command line.
    pub fn name(&self) -> &'static str {
        match self {
            Self::Translational => "translational",
            Self::Attitude => "attitude",
            Self::Full => "full",
        }
    }

    /// Parses a name as written by [`Formulation::name`].
    pub fn parse(name: &str) -> Result<Self> {
        Self::ALL
            .into_iter()
            .find(|f| f.name() == name)
            .ok_or_else(|| DataError::UnknownName {
                kind: "formulation",
                name: name.to_string(),
                known: "translational, attitude, full".to_string(),
            })
    }

    /// Names of the state variables x.
    pub fn state_names(&self) -> Vec<&'static str> {
        match self {
            Self::Translational => VELOCITY.to_vec(),
            Self::Attitude => RATE.to_vec(),
            Self::Full => VELOCITY.iter().chain(&RATE).copied().collect(),
        }
    }

    /// Names of the control inputs u.
    pub fn control_names(&self) -> Vec<&'static str> {
        match self {
            Self::Translational => THRUST_VECTOR.to_vec(),
            Self::Attitude => MOTOR_SPEED.to_vec(),
            Self::Full => MOTOR_SPEED_SQUARED.to_vec(),
        }
    }

    /// Names of X = [x, u], the inputs of the identified models.
    pub fn input_names(&self) -> Vec<&'static str> {
        let mut names = self.state_names();
        names.extend(self.control_names());
        names
    }

    /// Names of the targets ẋ, as `vdot_x` … `wdot_z`.
    pub fn target_names(&self) -> Vec<String> {
        self.state_names()
            .iter()
            .map(|s| s.replacen('_', "dot_", 1))
            .collect()
    }

    /// Number of states I.
    pub fn state_dim(&self) -> usize {
        self.state_names().len()
    }

    /// Number of controls U.
    pub fn control_dim(&self) -> usize {
        self.control_names().len()
    }

    fn state(&self, log: &FlightLog, k: usize, out: &mut Vec<f64>) {
        match self {
            Self::Translational => out.extend(log.velocity[k]),
            Self::Attitude => out.extend(log.body_rate[k]),
            Self::Full => {
                out.extend(log.velocity[k]);
                out.extend(log.body_rate[k]);
            }
        }
    }

    fn control(&self, log: &FlightLog, k: usize, out: &mut Vec<f64>) {
        match self {
            Self::Translational => {
                let thrust = log.thrust_setpoint[k];
                out.extend(log.rotation[k].iter().map(|row| row[2] * thrust));
            }
            Self::Attitude => out.extend(log.motor_command[k].iter().map(|p| p / 1000.0)),
            Self::Full => out.extend(log.motor_command[k].iter().map(|p| (p / 1000.0).powi(2))),
        }
    }

    /// Builds the regression data of rows `rows` of `log`: states, controls and the derivative of
    /// the states estimated on this segment alone.
    pub fn segment(
        &self,
        log: &FlightLog,
        rows: Range<usize>,
        derivative: Derivative,
    ) -> Result<Segment> {
        if rows.end > log.len() || rows.start >= rows.end {
            return Err(DataError::Invalid {
                what: log.path.display().to_string(),
                message: format!("rows {rows:?} are outside the {} samples", log.len()),
            });
        }
        let n = rows.len();
        let (dim_x, dim_u) = (self.state_dim(), self.control_dim());
        let mut buffer = Vec::with_capacity(dim_x + dim_u);
        let mut states = Mat::<f64>::zeros(n, dim_x);
        let mut controls = Mat::<f64>::zeros(n, dim_u);
        for (i, k) in rows.clone().enumerate() {
            buffer.clear();
            self.state(log, k, &mut buffer);
            self.control(log, k, &mut buffer);
            for j in 0..dim_x {
                states[(i, j)] = buffer[j];
            }
            for j in 0..dim_u {
                controls[(i, j)] = buffer[dim_x + j];
            }
        }
        let targets = derivative.apply_columns(states.as_ref(), log.sample_interval())?;
        Ok(Segment {
            formulation: *self,
            time: log.time[rows.clone()].to_vec(),
            rows,
            states,
            controls,
            targets,
        })
    }
}

/// Regression data of one contiguous stretch of a flight.
#[derive(Clone, Debug)]
pub struct Segment {
    pub formulation: Formulation,
    /// The rows of the flight this segment covers.
    pub rows: Range<usize>,
    /// Time of each sample, s.
    pub time: Vec<f64>,
    /// x, one row per sample.
    pub states: Mat<f64>,
    /// u, one row per sample.
    pub controls: Mat<f64>,
    /// ẋ estimated on this segment, one row per sample.
    pub targets: Mat<f64>,
}

impl Segment {
    /// Number of samples.
    pub fn len(&self) -> usize {
        self.states.nrows()
    }

    /// Whether the segment has no samples.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// X = [x, u], one row per sample.
    pub fn inputs(&self) -> Mat<f64> {
        let (n, dim_x, dim_u) = (self.len(), self.states.ncols(), self.controls.ncols());
        Mat::from_fn(n, dim_x + dim_u, |i, j| {
            if j < dim_x {
                self.states[(i, j)]
            } else {
                self.controls[(i, j - dim_x)]
            }
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_are_consistent() {
        assert_eq!(Formulation::Full.input_names().len(), 10);
        assert_eq!(
            Formulation::Attitude.target_names(),
            vec!["wdot_x", "wdot_y", "wdot_z"]
        );
        assert_eq!(Formulation::parse("full").unwrap(), Formulation::Full);
        let error = Formulation::parse("rotational").unwrap_err().to_string();
        assert!(error.contains("rotational") && error.contains("translational"));
    }
}
