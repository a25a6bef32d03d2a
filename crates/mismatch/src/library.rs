//! The library of candidate physics terms. Each candidate ([`CandidateId`]) is one effect of the
//! vocabulary (or, for the timing term, the first-order signature shared by a delay and a motor lag)
//! with named terms, their formulas and units. A term's column is the change of the model's matched prediction when
//! its coefficient moves away from zero, computed with the same forward model that later fits the
//! effect exactly, so the linear screen and the nonlinear fit describe the same physics.

use physics::{
    Delay, EffectId, Effects, GroundEffect, InertiaScale, LinearDrag, QuadraticDrag, ThrustScale,
    TorqueBias,
};
use serde::{Serialize, Serializer};

use crate::problem::{Channels, Problem};

/// One term of the library.
#[derive(Clone, Debug, Serialize)]
pub struct Term {
    pub name: String,
    pub formula: String,
    /// Units of the term's column (an acceleration per unit coefficient).
    pub units: String,
    /// The coefficient and its units.
    pub coefficient: String,
}

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
}

impl CandidateId {
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

fn term(name: &str, formula: &str, units: &str, coefficient: &str) -> Term {
    Term {
        name: name.to_string(),
        formula: formula.to_string(),
        units: units.to_string(),
        coefficient: coefficient.to_string(),
    }
}

/// The candidates for a problem and their columns (per analysed row, per channel).
pub fn build_library(problem: &Problem) -> (Vec<Candidate>, Vec<Vec<Channels>>) {
    let base = problem.predict(&Effects::default());
    let mut columns: Vec<Vec<Channels>> = Vec::new();
    let mut candidates = Vec::new();
    let mut specs = translational_candidates(problem.recording.dt);
    if problem.channels == 6 {
        specs.extend(attitude_candidates());
    }
    for CandidateSpec {
        id,
        terms,
        perturbed,
    } in specs
    {
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

/// A candidate before its columns are computed: each column is the model's response to one
/// perturbed effect set, divided by the perturbation's step.
struct CandidateSpec {
    id: CandidateId,
    terms: Vec<Term>,
    perturbed: Vec<(Effects, f64)>,
}

/// The effect set with `f` applied to the empty one.
fn with(f: &dyn Fn(&mut Effects)) -> Effects {
    let mut e = Effects::default();
    f(&mut e);
    e
}

const AXES: [&str; 3] = ["x", "y", "z"];

/// Relative step of the factor parameters' derivatives.
const STEP: f64 = 1e-3;

/// The candidates of the translational channels (`dt`: the recording's sample interval).
fn translational_candidates(dt: f64) -> Vec<CandidateSpec> {
    let step = STEP;
    let small_radius: f64 = 0.02;
    let timing_step = dt / 4.0;
    vec![
        CandidateSpec {
            id: CandidateId::ThrustScale,
            terms: vec![term("thrust", "R e3 T / m", "m/s²", "k − 1 (1)")],
            perturbed: vec![(
                with(&|e| e.thrust_scale = Some(ThrustScale { k: 1.0 + step })),
                step,
            )],
        },
        CandidateSpec {
            id: CandidateId::LinearDrag,
            terms: AXES
                .iter()
                .map(|a| {
                    term(
                        &format!("rotor_drag_{a}"),
                        &format!("−R e_{a} e_{a}ᵀ Rᵀ v"),
                        "m/s",
                        &format!("d{a} (1/s)"),
                    )
                })
                .collect(),
            perturbed: (0..3)
                .map(|i| {
                    let mut d = [0.0; 3];
                    d[i] = 1.0;
                    (with(&|e| e.linear_drag = Some(LinearDrag { d })), 1.0)
                })
                .collect(),
        },
        CandidateSpec {
            id: CandidateId::QuadraticDrag,
            terms: vec![term("air_drag", "−|v| v", "m²/s²", "c (1/m)")],
            perturbed: vec![(
                with(&|e| e.quadratic_drag = Some(QuadraticDrag { c: 1.0 })),
                1.0,
            )],
        },
        CandidateSpec {
            id: CandidateId::GroundEffect,
            terms: vec![term(
                "ground_thrust",
                "R e3 T / (16 m z²)",
                "1/s²",
                "r² (m²)",
            )],
            perturbed: vec![(
                with(&|e| e.ground_effect = Some(GroundEffect { r_m: small_radius })),
                small_radius * small_radius,
            )],
        },
        CandidateSpec {
            id: CandidateId::DelayOrMotorLag,
            terms: vec![term(
                "command_rate",
                "−d/dt (R e3 T / m, J⁻¹ τ)",
                "m/s³, rad/s³",
                "delay or lag time constant (s)",
            )],
            perturbed: vec![(
                with(&|e| {
                    e.delay = Some(Delay {
                        delay_s: timing_step,
                    })
                }),
                timing_step,
            )],
        },
    ]
}

/// The candidates that act on the angular channels only.
fn attitude_candidates() -> Vec<CandidateSpec> {
    let step = STEP;
    vec![
        CandidateSpec {
            id: CandidateId::TorqueBias,
            terms: AXES
                .iter()
                .map(|a| {
                    term(
                        &format!("torque_bias_{a}"),
                        &format!("e_{a}"),
                        "1",
                        &format!("b{a} (rad/s²)"),
                    )
                })
                .collect(),
            perturbed: (0..3)
                .map(|i| {
                    let mut b = [0.0; 3];
                    b[i] = 1.0;
                    (with(&|e| e.torque_bias = Some(TorqueBias { b })), 1.0)
                })
                .collect(),
        },
        CandidateSpec {
            id: CandidateId::InertiaScale,
            terms: AXES
                .iter()
                .map(|a| {
                    term(
                        &format!("torque_response_{a}"),
                        &format!("e_{a} e_{a}ᵀ J⁻¹ (τ − ω × J ω)"),
                        "rad/s²",
                        &format!("1/k{a} − 1 (1)"),
                    )
                })
                .collect(),
            perturbed: (0..3)
                .map(|i| {
                    let mut k = [1.0; 3];
                    k[i] = 1.0 / (1.0 + step);
                    (with(&|e| e.inertia_scale = Some(InertiaScale { k })), step)
                })
                .collect(),
        },
    ]
}
