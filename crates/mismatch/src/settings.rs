//! The settings of both pipelines, the single-recording analysis ([`crate::analyze`]) and the
//! joint analysis of a fleet ([`crate::fleet::identify`]), checked once: [`Settings`] →
//! [`Settings::checked`] → [`CheckedSettings`], which both take (as linfa's and sindy's
//! parameters are checked before a fit).
//!
//! What the two share, the comparison (its test function and held-out part), is one
//! [`ComparisonSettings`]; each records it with its own part ([`AnalysisRecord`],
//! [`FleetRecord`]).

use std::ops::Bound::{self, Excluded, Included, Unbounded};
use std::ops::RangeBounds;

use serde::Serialize;
use sindy::stability::SelectionSettings;
use sindy::weak_form::TestFunction;

use crate::error::{MismatchError, Result};
use crate::explain::evidence::EvidenceSettings;
use crate::improve::estimate::EstimateSettings;

/// Every setting of the mismatch analyses; [`Settings::checked`] before use.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct Settings {
    pub comparison: ComparisonSettings,
    pub analysis: AnalysisSettings,
    pub fleet: FleetSettings,
}

/// The comparison of recordings with a model, shared by both pipelines.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct ComparisonSettings {
    /// The weak form's test function.
    pub test_function: TestFunction,
    /// Fraction of the analysed rows, at the end, held out from every fit and choice.
    pub heldout_fraction: f64,
}

impl Default for ComparisonSettings {
    fn default() -> Self {
        Self {
            test_function: TestFunction::default(),
            heldout_fraction: 0.3,
        }
    }
}

/// The single-recording analysis's own settings.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct AnalysisSettings {
    /// Length of the blocks that the selection and the evidence rule compare, s.
    pub block_s: f64,
    pub selection: SelectionSettings,
    pub evidence: EvidenceSettings,
    /// The final estimate of the named effects' parameters ([`crate::improve::estimate`]).
    pub estimate: EstimateSettings,
    #[serde(flatten)]
    pub locate: LocateSettings,
    /// Levenberg–Marquardt iterations of a joint fit (the evidence rule's refits take half).
    pub iterations: usize,
    /// What to do with a recording without measurement noise
    /// ([`crate::recording::degenerate::check_noise`]).
    #[serde(skip)]
    pub noise_free: NoiseFree,
}

impl Default for AnalysisSettings {
    fn default() -> Self {
        Self {
            block_s: 1.0,
            selection: SelectionSettings::default(),
            evidence: EvidenceSettings::default(),
            estimate: EstimateSettings::default(),
            locate: LocateSettings::default(),
            iterations: 40,
            noise_free: NoiseFree::Refuse,
        }
    }
}

/// Where a channel, and a window of it, is said to disagree with the model.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct LocateSettings {
    /// A channel is significant when its residual RMS exceeds this multiple of its noise floor.
    pub significance_factor: f64,
    /// A window is located where the moving RMS of the residual exceeds this multiple of the floor.
    pub window_factor: f64,
    /// Length of the moving RMS, s.
    pub window_s: f64,
    /// Shortest window reported, s.
    pub min_window_s: f64,
}

impl Default for LocateSettings {
    fn default() -> Self {
        Self {
            significance_factor: 2.0,
            window_factor: 2.5,
            window_s: 1.0,
            min_window_s: 0.5,
        }
    }
}

/// What [`crate::analyze`] does with a recording whose noise floor is below the comparison's
/// accuracy.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum NoiseFree {
    /// Refuse it: the evidence rule measures residuals in units of the noise.
    #[default]
    Refuse,
    /// Analyse it anyway, for development on noise-free simulations (the estimates are
    /// meaningful; the evidence, the windows and the significance are not).
    Analyse,
}

/// The joint analysis's own settings.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct FleetSettings {
    /// An effect joins when it lowers the held-out (or transfer) error by at least this fraction.
    pub min_step: f64,
    /// Levenberg–Marquardt iterations of a joint fit.
    pub iterations: usize,
}

impl Default for FleetSettings {
    fn default() -> Self {
        Self {
            min_step: 0.05,
            iterations: 30,
        }
    }
}

/// Settings every value of which lies in its range; only [`Settings::checked`] makes one.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CheckedSettings(Settings);

impl std::ops::Deref for CheckedSettings {
    type Target = Settings;

    fn deref(&self) -> &Settings {
        &self.0
    }
}

impl CheckedSettings {
    /// The default settings (in range by construction; a unit test checks it).
    pub fn standard() -> Self {
        Self(Settings::default())
    }

    /// What an analysis of one recording records.
    pub fn analysis_record(&self) -> AnalysisRecord {
        AnalysisRecord {
            comparison: self.comparison,
            analysis: self.analysis,
        }
    }

    /// What a joint analysis records.
    pub fn fleet_record(&self) -> FleetRecord {
        FleetRecord {
            comparison: self.comparison,
            fleet: self.fleet,
        }
    }
}

/// The settings an analysis of one recording used (recorded in `mismatch.json`).
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct AnalysisRecord {
    #[serde(flatten)]
    pub comparison: ComparisonSettings,
    #[serde(flatten)]
    pub analysis: AnalysisSettings,
}

/// The settings a joint analysis used (recorded in its report).
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct FleetRecord {
    #[serde(flatten)]
    pub comparison: ComparisonSettings,
    #[serde(flatten)]
    pub fleet: FleetSettings,
}

impl Settings {
    /// These settings, each value checked against its range; the first out of range is named.
    pub fn checked(self) -> Result<CheckedSettings> {
        let Self {
            comparison:
                ComparisonSettings {
                    test_function,
                    heldout_fraction,
                },
            analysis,
            fleet,
        } = self;
        let AnalysisSettings {
            selection,
            evidence,
            estimate,
            locate,
            ..
        } = analysis;
        let positive = (Excluded(0.0), Unbounded);
        let non_negative = (Included(0.0), Unbounded);
        let fraction = (Excluded(0.0), Excluded(1.0));
        let share = (Included(0.0), Excluded(1.0));
        let at_least = |low: f64| (Included(low), Unbounded);
        let ranges: [(&'static str, f64, Range); 21] = [
            (
                "comparison.test_function.half_width_s",
                test_function.half_width_s,
                positive,
            ),
            (
                "comparison.test_function.power",
                test_function.power as f64,
                at_least(1.0),
            ),
            ("comparison.heldout_fraction", heldout_fraction, fraction),
            ("analysis.block_s", analysis.block_s, positive),
            (
                "analysis.iterations",
                analysis.iterations as f64,
                at_least(1.0),
            ),
            (
                "analysis.selection.folds",
                selection.folds as f64,
                at_least(2.0),
            ),
            (
                "analysis.selection.resamples",
                selection.resamples as f64,
                at_least(1.0),
            ),
            (
                "analysis.selection.stability_threshold",
                selection.stability_threshold,
                (Excluded(0.0), Included(1.0)),
            ),
            (
                "analysis.selection.min_gain",
                selection.min_gain,
                non_negative,
            ),
            (
                "analysis.evidence.significance",
                evidence.significance,
                fraction,
            ),
            (
                "analysis.evidence.min_gain",
                evidence.min_gain,
                non_negative,
            ),
            (
                "analysis.evidence.min_trimmed_gain",
                evidence.min_trimmed_gain,
                non_negative,
            ),
            (
                "analysis.evidence.min_heldout_reduction",
                evidence.min_heldout_reduction,
                share,
            ),
            (
                "analysis.estimate.huber_threshold",
                estimate.huber_threshold,
                positive,
            ),
            (
                "analysis.estimate.passes",
                estimate.passes as f64,
                at_least(1.0),
            ),
            (
                "analysis.significance_factor",
                locate.significance_factor,
                positive,
            ),
            ("analysis.window_factor", locate.window_factor, positive),
            ("analysis.window_s", locate.window_s, positive),
            ("analysis.min_window_s", locate.min_window_s, non_negative),
            ("fleet.min_step", fleet.min_step, share),
            ("fleet.iterations", fleet.iterations as f64, at_least(1.0)),
        ];
        for (setting, value, range) in ranges {
            check(setting, value, range)?;
        }
        Ok(CheckedSettings(self))
    }
}

/// A setting's range: its lower and upper bound.
type Range = (Bound<f64>, Bound<f64>);

/// `value` finite and within `range`, or an error naming the setting and the range.
fn check(setting: &'static str, value: f64, range: Range) -> Result<()> {
    if value.is_finite() && range.contains(&value) {
        return Ok(());
    }
    let low = match range.0 {
        Included(low) => format!("[{low}"),
        Excluded(low) => format!("({low}"),
        Unbounded => "(−∞".to_string(),
    };
    let high = match range.1 {
        Included(high) => format!("{high}]"),
        Excluded(high) => format!("{high})"),
        Unbounded => "∞)".to_string(),
    };
    Err(MismatchError::Setting {
        setting,
        message: format!("must lie in {low}, {high}, got {value}"),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_defaults_are_in_range() {
        assert_eq!(
            Settings::default().checked().unwrap(),
            CheckedSettings::standard()
        );
    }

    #[test]
    fn a_value_out_of_range_is_named() {
        let mut settings = Settings::default();
        settings.comparison.heldout_fraction = 1.0;
        let message = settings.checked().unwrap_err().to_string();
        assert!(message.contains("comparison.heldout_fraction"), "{message}");
        let mut settings = Settings::default();
        settings.analysis.locate.window_s = f64::NAN;
        let message = settings.checked().unwrap_err().to_string();
        assert!(message.contains("analysis.window_s"), "{message}");
        let mut settings = Settings::default();
        settings.fleet.iterations = 0;
        assert!(
            settings
                .checked()
                .unwrap_err()
                .to_string()
                .contains("fleet.iterations")
        );
    }

    /// Both records keep the field names and order the outputs had before the settings were one
    /// type, so that `mismatch.json` and the fleet report read as before.
    #[test]
    fn the_records_keep_the_outputs_fields() {
        let settings = CheckedSettings::standard();
        let keys_in_order = |text: String, keys: &[&str]| {
            let at: Vec<usize> = keys
                .iter()
                .map(|k| text.find(&format!("\"{k}\":")).unwrap())
                .collect();
            assert!(at.windows(2).all(|w| w[0] < w[1]), "{text}");
            assert_eq!(text.matches("\":").count() - nested_keys(&text), keys.len());
        };
        let analysis = serde_json::to_string(&settings.analysis_record()).unwrap();
        keys_in_order(
            analysis,
            &[
                "test_function",
                "heldout_fraction",
                "block_s",
                "selection",
                "evidence",
                "estimate",
                "significance_factor",
                "window_factor",
                "window_s",
                "min_window_s",
                "iterations",
            ],
        );
        let fleet = serde_json::to_string(&settings.fleet_record()).unwrap();
        keys_in_order(
            fleet,
            &[
                "test_function",
                "heldout_fraction",
                "min_step",
                "iterations",
            ],
        );
    }

    /// Keys inside nested objects of a compact JSON text (those below the top level).
    fn nested_keys(text: &str) -> usize {
        let mut depth = 0;
        let mut count = 0;
        let bytes = text.as_bytes();
        for (i, b) in bytes.iter().enumerate() {
            match b {
                b'{' => depth += 1,
                b'}' => depth -= 1,
                b':' if depth > 1 && i > 0 && bytes[i - 1] == b'"' => count += 1,
                _ => {}
            }
        }
        count
    }
}
