//! The library of candidate physics terms. Each candidate ([`CandidateId`]) is one effect of the
//! vocabulary (or, for the timing term, the first-order signature shared by a delay and a motor lag)
//! with named terms, their formulas and units. A term's column is the change of the model's matched prediction when
//! its coefficient moves away from zero, computed with the same forward model that later fits the
//! effect exactly, so the linear screen and the nonlinear fit describe the same physics.

use physics::{ChannelGroup, EffectId, Effects};
use serde::{Serialize, Serializer};

pub use physics::Term;

use crate::locate::problem::{Channels, Problem};

/// What a candidate of the library stands for: one effect of the vocabulary, or the first-order
/// timing signature a delay and a motor lag share (resolved into either or both by the fit).
/// Serialises and displays as the effect's id, or `delay_or_motor_lag`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CandidateId {
    ThrustScale,
    LinearDrag,
    QuadraticDrag,
    GroundEffect,
    DelayOrMotorLag,
    TorqueBias,
    InertiaScale,
    AerodynamicTorque,
}

impl CandidateId {
    /// Every candidate, in the library's order (its columns' order).
    pub const ALL: [CandidateId; 8] = [
        Self::ThrustScale,
        Self::LinearDrag,
        Self::QuadraticDrag,
        Self::GroundEffect,
        Self::DelayOrMotorLag,
        Self::TorqueBias,
        Self::InertiaScale,
        Self::AerodynamicTorque,
    ];

    /// The effect whose screening terms the candidate's are (the timing term's are the delay's).
    pub const fn screened_effect(self) -> EffectId {
        match self.effect() {
            Some(id) => id,
            None => EffectId::Delay,
        }
    }

    /// The effect the candidate stands for (none for the timing term).
    pub const fn effect(self) -> Option<EffectId> {
        match self {
            Self::ThrustScale => Some(EffectId::ThrustScale),
            Self::LinearDrag => Some(EffectId::LinearDrag),
            Self::QuadraticDrag => Some(EffectId::QuadraticDrag),
            Self::GroundEffect => Some(EffectId::GroundEffect),
            Self::DelayOrMotorLag => None,
            Self::TorqueBias => Some(EffectId::TorqueBias),
            Self::InertiaScale => Some(EffectId::InertiaScale),
            Self::AerodynamicTorque => Some(EffectId::AerodynamicTorque),
        }
    }

    /// The effect's id, or `delay_or_motor_lag` for the timing term.
    pub const fn name(self) -> &'static str {
        match self.effect() {
            Some(id) => id.name(),
            None => "delay_or_motor_lag",
        }
    }
}

impl std::fmt::Display for CandidateId {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.pad(self.name())
    }
}

impl Serialize for CandidateId {
    fn serialize<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        serializer.serialize_str(self.name())
    }
}

/// A group of terms that stands for one effect.
#[derive(Clone, Debug, Serialize)]
pub struct Candidate {
    pub id: CandidateId,
    pub terms: Vec<Term>,
    /// Indices of the candidate's columns in the design.
    #[serde(skip)]
    pub columns: Vec<usize>,
}

/// The candidates for a problem and their columns (per analysed row, per channel): each effect's
/// screening terms ([`physics::EffectKind::screening`]), the angular ones only when the problem
/// has the angular channels.
pub fn build_library(problem: &Problem) -> (Vec<Candidate>, Vec<Vec<Channels>>) {
    let base = problem.predict(&Effects::default());
    let mut columns: Vec<Vec<Channels>> = Vec::new();
    let mut candidates = Vec::new();
    for id in CandidateId::ALL {
        let effect = id.screened_effect();
        if effect.acts_on() == ChannelGroup::Angular && problem.channels != 6 {
            continue;
        }
        // The height above the ground comes from the logged position.
        if id == CandidateId::GroundEffect && !problem.recording.position_logged {
            continue;
        }
        let Some((terms, perturbed)) = effect.screening(problem.recording.dt()) else {
            continue;
        };
        let start = columns.len();
        for (effects, step) in perturbed {
            let predicted = problem.predict(&effects);
            columns.push(
                predicted
                    .iter()
                    .zip(&base)
                    .map(|(p, b)| {
                        let mut out = [0.0; 6];
                        for c in 0..6 {
                            out[c] = (p[c] - b[c]) / step;
                        }
                        out
                    })
                    .collect(),
            );
        }
        candidates.push(Candidate {
            id,
            terms,
            columns: (start..columns.len()).collect(),
        });
    }
    (candidates, columns)
}
