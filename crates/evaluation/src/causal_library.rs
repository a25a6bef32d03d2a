//! A library built from one segment in time order: terms of X = [x, u] at each sample, and
//! first-order lags of the controls (the motors do not reach a commanded speed or thrust at once).
//!
//! Features, in this order (names in brackets):
//! - `linear`: every input [`x_j`], [`u_j`];
//! - `fourier` K: `sin(k·z)`, `cos(k·z)` of every input z, k = 1..=K (as [`sindy::LibrarySpec`]);
//! - `control_squares`: [`u_j^2`];
//! - `control_lags` a ∈ [0, 1): `s[k] = a·s[k−1] + (1 − a)·u[k]`, `s[0] = u[0]`
//!   [`lag0.80(u_j)`], a discrete first-order lag with time constant −dt/ln a.
//!
//! Every feature at sample k uses samples 0..=k of the same segment only: nothing crosses from one
//! segment to the other, and nothing from the future of a sample is used. The constant is left to
//! the regression (its intercept).

use crate::segment::Segment;
use learn::Formulation;

use serde::{Deserialize, Serialize};

use sindy::{MAX_FEATURES, Mat, Result, field};

/// The most control lags a causal library may hold (each adds one feature per control; the
/// committed variants use 3).
pub const MAX_CONTROL_LAGS: usize = 100;

/// Which terms the library holds (unchecked; checked by [`CausalLibrary::validate`], which
/// [`CausalLibrary::features`] calls).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CausalLibrary {
    #[serde(default)]
    pub linear: bool,
    /// Fourier frequencies K (0: none).
    #[serde(default)]
    pub fourier: usize,
    #[serde(default)]
    pub control_squares: bool,
    /// Poles a of the control lags.
    #[serde(default)]
    pub control_lags: Vec<f64>,
}

impl CausalLibrary {
    /// Checks the settings: at most [`MAX_CONTROL_LAGS`] lags, each pole in [0, 1) and none listed
    /// twice, at least one feature, and at most [`sindy::MAX_FEATURES`] features on every
    /// formulation. Errors are [`sindy::SindyError::Field`] naming the field (`control_lags`,
    /// `fourier`; empty for the library as a whole).
    pub fn validate(&self) -> Result<()> {
        if self.control_lags.len() > MAX_CONTROL_LAGS {
            return Err(field(
                "control_lags",
                format!(
                    "{} lags, more than the limit of {MAX_CONTROL_LAGS} (evaluation::MAX_CONTROL_LAGS)",
                    self.control_lags.len()
                ),
            ));
        }
        if let Some(a) = self
            .control_lags
            .iter()
            .find(|a| !(a.is_finite() && **a >= 0.0 && **a < 1.0))
        {
            return Err(field(
                "control_lags",
                format!("pole {a} must lie in [0, 1)"),
            ));
        }
        // Exact equality (`==`, so 0 and -0 are one pole): two equal poles give two identical,
        // collinear columns. No tolerance: the poles are read from decimal text, and the same text
        // always parses to the same f64, so no arithmetic noise can separate two copies of a pole;
        // poles that differ at all are different filters, and how close two may be before their
        // columns are too nearly collinear is the regression's conditioning (its penalty), not a
        // threshold to pick here.
        for (index, a) in self.control_lags.iter().enumerate() {
            if self.control_lags[..index].contains(a) {
                return Err(field("control_lags", format!("pole {a} is listed twice")));
            }
        }
        if self.fourier > MAX_FEATURES / 2 {
            return Err(field(
                "fourier",
                format!(
                    "{} frequencies give more than the limit of {MAX_FEATURES} features \
                     (sindy::MAX_FEATURES) on a single input",
                    self.fourier
                ),
            ));
        }
        if !self.linear
            && self.fourier == 0
            && !self.control_squares
            && self.control_lags.is_empty()
        {
            return Err(field("", "the library has no feature"));
        }
        for formulation in Formulation::ALL {
            let (inputs, controls) = (formulation.input_names().len(), formulation.control_dim());
            let count = self.feature_count(inputs, controls);
            if count > MAX_FEATURES {
                return Err(field(
                    "",
                    format!(
                        "{count} features on the {} formulation ({inputs} inputs, {controls} \
                         controls), more than the limit of {MAX_FEATURES} (sindy::MAX_FEATURES)",
                        formulation.name()
                    ),
                ));
            }
        }
        Ok(())
    }

    /// The number of features on `inputs` inputs of which `controls` are controls (saturating).
    pub fn feature_count(&self, inputs: usize, controls: usize) -> usize {
        let per_input = usize::from(self.linear).saturating_add(self.fourier.saturating_mul(2));
        let per_control = usize::from(self.control_squares).saturating_add(self.control_lags.len());
        per_input
            .saturating_mul(inputs)
            .saturating_add(per_control.saturating_mul(controls))
    }

    /// Θ of `segment` (one row per sample) and the feature names: a control lag is named by its
    /// pole with two decimals, or as many more as it takes to tell the poles apart (up to 17; past
    /// that, in the shortest form that tells them apart).
    pub fn features(&self, segment: &Segment) -> Result<(Mat<f64>, Vec<String>)> {
        self.validate()?;
        let formulation = segment.formulation;
        let inputs = segment.inputs();
        let input_names = formulation.input_names();
        let control_names = formulation.control_names();
        let n = segment.len();
        let mut columns: Vec<Vec<f64>> = Vec::new();
        let mut names: Vec<String> = Vec::new();
        let input = |j: usize| -> Vec<f64> { inputs.col(j).iter().copied().collect() };
        let control = |j: usize| -> Vec<f64> { segment.controls.col(j).iter().copied().collect() };
        if self.linear {
            for (j, name) in input_names.iter().enumerate() {
                columns.push(input(j));
                names.push(name.to_string());
            }
        }
        for k in 1..=self.fourier {
            let prefix = if k == 1 {
                String::new()
            } else {
                format!("{k}*")
            };
            for (j, name) in input_names.iter().enumerate() {
                let values = input(j);
                columns.push(values.iter().map(|v| (k as f64 * v).sin()).collect());
                names.push(format!("sin({prefix}{name})"));
                columns.push(values.iter().map(|v| (k as f64 * v).cos()).collect());
                names.push(format!("cos({prefix}{name})"));
            }
        }
        if self.control_squares {
            for (j, name) in control_names.iter().enumerate() {
                columns.push(control(j).iter().map(|v| v * v).collect());
                names.push(format!("{name}^2"));
            }
        }
        let labels = pole_labels(&self.control_lags);
        for (&pole, label) in self.control_lags.iter().zip(&labels) {
            for (j, name) in control_names.iter().enumerate() {
                columns.push(first_order_lag(&control(j), pole));
                names.push(format!("lag{label}({name})"));
            }
        }
        let theta = Mat::from_fn(n, columns.len(), |i, j| columns[j][i]);
        Ok((theta, names))
    }
}

/// The fewest decimals, at least two and at most 17, with which the (distinct) `poles` print
/// differently; `None` when no such count tells them apart (poles closer than 1e-17, e.g. 0 and
/// 1e-20).
fn distinct_decimals(poles: &[f64]) -> Option<usize> {
    (2..=17).find(|&decimals| {
        let mut printed: Vec<String> = poles.iter().map(|p| format!("{p:.decimals$}")).collect();
        printed.sort();
        printed.windows(2).all(|pair| pair[0] != pair[1])
    })
}

/// The poles as written in feature names: with [`distinct_decimals`] fixed decimals, else in
/// Rust's shortest round-trip form (`0.00000000000000000001` for 1e-20), which prints distinct
/// values differently.
fn pole_labels(poles: &[f64]) -> Vec<String> {
    match distinct_decimals(poles) {
        Some(decimals) => poles.iter().map(|p| format!("{p:.decimals$}")).collect(),
        None => poles.iter().map(|p| format!("{p}")).collect(),
    }
}

/// `s[k] = a·s[k−1] + (1 − a)·u[k]`, `s[0] = u[0]`.
pub fn first_order_lag(signal: &[f64], pole: f64) -> Vec<f64> {
    let mut state = signal.first().copied().unwrap_or(0.0);
    signal
        .iter()
        .map(|&u| {
            state = pole * state + (1.0 - pole) * u;
            state
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::segment::Segment;
    use learn::Formulation;
    use sindy::SindyError;

    #[test]
    fn lags_are_causal_first_order_filters() {
        let step: Vec<f64> = (0..6).map(|k| if k < 2 { 0.0 } else { 1.0 }).collect();
        let lagged = first_order_lag(&step, 0.5);
        assert_eq!(lagged, vec![0.0, 0.0, 0.5, 0.75, 0.875, 0.9375]);
        // Changing a later sample never changes an earlier output.
        let mut later = step.clone();
        later[4] = 10.0;
        assert_eq!(first_order_lag(&later, 0.5)[..4], lagged[..4]);
        assert_eq!(first_order_lag(&step, 0.0), step);
    }

    #[test]
    fn lag_names_carry_the_decimals_that_tell_the_poles_apart() {
        assert_eq!(distinct_decimals(&[0.5, 0.8, 0.95]), Some(2));
        assert_eq!(distinct_decimals(&[0.951, 0.954]), Some(3));
        assert_eq!(distinct_decimals(&[0.5, 0.5 + 1e-12]), Some(12));
        assert_eq!(distinct_decimals(&[0.0, 1e-17]), Some(17));
        assert_eq!(distinct_decimals(&[]), Some(2));
        assert_eq!(pole_labels(&[0.5, 0.8, 0.95]), ["0.50", "0.80", "0.95"]);
        // No count of decimals up to 17 tells 0 from 1e-20: the shortest round-trip form does.
        assert_eq!(distinct_decimals(&[0.0, 1e-20]), None);
        assert_eq!(pole_labels(&[0.0, 1e-20]), ["0", "0.00000000000000000001"]);
    }

    #[test]
    fn poles_closer_than_the_printed_decimals_still_give_distinct_feature_names() {
        let library = CausalLibrary {
            control_lags: vec![0.0, 1e-20],
            ..Default::default()
        };
        let formulation = Formulation::Translational;
        let n = 4;
        let segment = Segment {
            formulation,
            rows: 0..n,
            time: (0..n).map(|k| k as f64 * 0.02).collect(),
            states: Mat::zeros(n, formulation.state_dim()),
            controls: Mat::from_fn(n, formulation.control_dim(), |i, j| (i + j) as f64),
            targets: Mat::zeros(n, formulation.state_dim()),
        };
        let (_, names) = library.features(&segment).unwrap();
        let first = formulation.control_names()[0];
        let lags: Vec<&String> = names
            .iter()
            .filter(|n| n.ends_with(&format!("({first})")))
            .collect();
        assert_eq!(
            lags,
            [
                &format!("lag0({first})"),
                &format!("lag0.00000000000000000001({first})")
            ]
        );
        let mut unique = names.clone();
        unique.sort();
        unique.dedup();
        assert_eq!(unique.len(), names.len(), "{names:?}");
    }

    #[test]
    fn settings_are_checked_with_the_field_they_are_in() {
        let cases = [
            (
                CausalLibrary {
                    control_lags: vec![0.5; MAX_CONTROL_LAGS + 1],
                    ..Default::default()
                },
                "control_lags",
                "101 lags, more than the limit of 100",
            ),
            (
                CausalLibrary {
                    control_lags: vec![0.5, 1.0],
                    ..Default::default()
                },
                "control_lags",
                "pole 1 must lie in [0, 1)",
            ),
            (
                CausalLibrary {
                    control_lags: vec![0.5, 0.8, 0.95, 0.8],
                    ..Default::default()
                },
                "control_lags",
                "pole 0.8 is listed twice",
            ),
            (
                CausalLibrary {
                    control_lags: vec![0.0, -0.0],
                    ..Default::default()
                },
                "control_lags",
                "is listed twice",
            ),
            (
                CausalLibrary {
                    fourier: 1_000_000_000,
                    ..Default::default()
                },
                "fourier",
                "limit of 10000",
            ),
            (CausalLibrary::default(), "", "no feature"),
            (
                CausalLibrary {
                    fourier: 4_000,
                    ..Default::default()
                },
                "",
                "features on the",
            ),
        ];
        for (library, expected_field, expected) in cases {
            match library.validate().unwrap_err() {
                SindyError::Field { field, message } => {
                    assert_eq!(field, expected_field, "{message}");
                    assert!(message.contains(expected), "{message}");
                }
                other => panic!("{other}"),
            }
        }
        let committed = CausalLibrary {
            linear: true,
            fourier: 1,
            control_squares: false,
            control_lags: vec![0.5, 0.8, 0.95],
        };
        committed.validate().unwrap();
        assert_eq!(committed.feature_count(7, 4), 7 * 3 + 4 * 3);
    }
}
