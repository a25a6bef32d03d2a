//! A recording longer than one analysis takes, analysed in consecutive parts: memory bounded by
//! one part's, time linear in the recording's length.
//!
//! The rows are cut into the fewest equal parts of at most a given number of rows (by default
//! [`MAX_ANALYSED_ROWS`], the most one analysis accepts); each part
//! is analysed on its own ([`analyze_observed`]: its own comparison, evidence and held-out last
//! 30 %), one after another (each on all threads). Only each part's report is kept. An effect is
//! named for the recording when more than half of the analysed parts name it; each number of its
//! parameters is pooled over the parts that named it by inverse-variance weights, and the parts'
//! spread about it is tested (`χ²` beyond its 99.9 % quantile: "varies").
//! A part that cannot be analysed (nothing moves in it, say) is listed with its reason; the others
//! are pooled.

use std::ops::Range;
use std::path::Path;

use data::FlightLog;
use physics::NominalModel;
use report::mismatch::parts::{
    PartLine, PartValue, PartsView, PooledEffect, PooledNumber, PooledParameter,
};
use serde::Serialize;
use statrs::distribution::{ChiSquared, ContinuousCDF};

use super::{Report, Stage, analyze_observed};
use crate::error::{MismatchError, Result};
use crate::recording::degenerate::MAX_ANALYSED_ROWS;
use crate::settings::CheckedSettings;

/// The `χ²` quantile beyond which the parts' values are said to vary.
const VARIES_QUANTILE: f64 = 0.999;

/// The fewest rows a part may hold (25 one-second blocks at 50 Hz).
pub const MIN_PART_ROWS: usize = 1_250;

/// Fails unless `part_rows` is from [`MIN_PART_ROWS`] to [`MAX_ANALYSED_ROWS`].
pub fn check_part_rows(part_rows: usize) -> Result<()> {
    if (MIN_PART_ROWS..=MAX_ANALYSED_ROWS).contains(&part_rows) {
        return Ok(());
    }
    Err(MismatchError::Setting {
        setting: "part_rows",
        message: format!(
            "{part_rows} rows per part; it must be from {MIN_PART_ROWS} (25 s at 50 Hz) to {MAX_ANALYSED_ROWS} (the most one analysis takes)"
        ),
    })
}

/// The consecutive row ranges of `rows` rows: the fewest equal parts of at most `part_rows` rows
/// (one part when the recording fits in one).
pub fn part_ranges(rows: usize, part_rows: usize) -> Vec<Range<usize>> {
    let parts = rows.div_ceil(part_rows.max(1)).max(1);
    (0..parts)
        .map(|i| i * rows / parts..(i + 1) * rows / parts)
        .collect()
}

/// One part: where it lies and its report, or why it could not be analysed.
#[derive(Clone, Debug, Serialize)]
pub struct Part {
    /// Data rows `[start, end)` of the analysed log, counted from 0.
    pub rows: [usize; 2],
    pub t_start: f64,
    pub t_end: f64,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub report: Option<Report>,
    /// The one-line reason a part was not analysed.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub refused: Option<String>,
}

/// A long recording's analysis: every part and the effects pooled over them (`mismatch.json`).
#[derive(Clone, Debug, Serialize)]
pub struct PartedAnalysis {
    pub recording: String,
    pub model: String,
    pub rows: usize,
    pub part_rows: usize,
    /// Held-out MSE before and after, averaged over the analysed parts by their rows.
    pub heldout: [f64; 2],
    pub effects: Vec<PooledEffect>,
    pub parts: Vec<Part>,
}

/// Analyses `log` in parts of at most `part_rows` rows ([`part_ranges`]; from [`MIN_PART_ROWS`]
/// to [`MAX_ANALYSED_ROWS`]), telling `observe` the part (from 0), the pass and the stage as each
/// begins. Fails when no part could be analysed, or on an error that is not a part's own (a model
/// the recording does not fit, say).
pub fn analyze_in_parts(
    log: &FlightLog,
    part_rows: usize,
    model: &NominalModel,
    model_name: &str,
    settings: &CheckedSettings,
    observe: &(dyn Fn(usize, usize, Stage) + Sync),
) -> Result<PartedAnalysis> {
    check_part_rows(part_rows)?;
    let ranges = part_ranges(log.len(), part_rows);
    let parts: Vec<Part> = ranges
        .iter()
        .enumerate()
        .map(|(index, rows)| {
            let part = log
                .row_range(rows.clone())
                .expect("a part lies inside the log");
            let analysed = analyze_observed(&part, model, model_name, settings, &|pass, stage| {
                observe(index, pass, stage)
            });
            let report = match analysed {
                Ok(analysis) => Some(analysis.report),
                Err(error @ MismatchError::Degenerate { .. }) => {
                    return Ok(part_of(&part, rows, None, Some(error.to_string())));
                }
                Err(error) => return Err(error),
            };
            Ok(part_of(&part, rows, report, None))
        })
        .collect::<Result<_>>()?;
    let analysed: Vec<&Report> = parts.iter().filter_map(|p| p.report.as_ref()).collect();
    if analysed.is_empty() {
        let reason = parts[0].refused.clone().unwrap_or_default();
        return Err(MismatchError::Recording {
            path: log.path.clone(),
            message: format!("no part of the recording could be analysed (the first: {reason})"),
        });
    }
    Ok(PartedAnalysis {
        recording: log.path.display().to_string(),
        model: model_name.to_string(),
        rows: log.len(),
        part_rows: ranges.iter().map(|r| r.len()).max().unwrap_or(0),
        heldout: pooled_heldout(&parts),
        effects: pooled_effects(&parts),
        parts,
    })
}

fn part_of(
    part: &FlightLog,
    rows: &Range<usize>,
    report: Option<Report>,
    refused: Option<String>,
) -> Part {
    Part {
        rows: [rows.start, rows.end],
        t_start: part.time[0],
        t_end: part.time[part.len() - 1],
        report,
        refused,
    }
}

/// The held-out MSEs averaged over the analysed parts, weighted by their rows.
fn pooled_heldout(parts: &[Part]) -> [f64; 2] {
    let (mut sum, mut weight) = ([0.0; 2], 0.0);
    for part in parts {
        if let Some(report) = &part.report {
            let rows = (part.rows[1] - part.rows[0]) as f64;
            sum[0] += rows * report.fit.heldout.before.mse;
            sum[1] += rows * report.fit.heldout.after.mse;
            weight += rows;
        }
    }
    [sum[0] / weight, sum[1] / weight]
}

/// Every effect some part named, in the order first named, with its numbers pooled.
fn pooled_effects(parts: &[Part]) -> Vec<PooledEffect> {
    let reports: Vec<Option<&Report>> = parts.iter().map(|p| p.report.as_ref()).collect();
    let analysed = reports.iter().flatten().count();
    let mut ids = Vec::new();
    for report in reports.iter().flatten() {
        for effect in &report.effects {
            if !ids.contains(&effect.id) {
                ids.push(effect.id);
            }
        }
    }
    ids.into_iter()
        .map(|id| {
            let found: Vec<Option<&super::EffectReport>> = reports
                .iter()
                .map(|r| r.and_then(|r| r.effects.iter().find(|e| e.id == id)))
                .collect();
            let named_in = found.iter().flatten().count();
            let template = found.iter().flatten().next().expect("named in some part");
            let parameters = template
                .parameters
                .values()
                .into_iter()
                .enumerate()
                .map(|(p, (name, value))| PooledParameter {
                    name: name.to_string(),
                    numbers: (0..value.numbers().len())
                        .map(|k| pooled_number(&found, p, k))
                        .collect(),
                })
                .collect();
            PooledEffect {
                id: id.name().to_string(),
                named_in,
                named: 2 * named_in > analysed,
                parameters,
            }
        })
        .collect()
}

/// Number `k` of parameter `p` pooled over the parts that named the effect.
fn pooled_number(found: &[Option<&super::EffectReport>], p: usize, k: usize) -> PooledNumber {
    pool(
        found
            .iter()
            .map(|effect| {
                effect.map(|effect| {
                    let (name, value) = &effect.parameters.values()[p];
                    let standard_error = effect
                        .standard_errors
                        .as_ref()
                        .and_then(|errors| errors.get(name))
                        .map(|e| e.numbers()[k])
                        .filter(|s| s.is_finite() && *s > 0.0);
                    PartValue {
                        value: value.numbers()[k],
                        standard_error,
                    }
                })
            })
            .collect(),
    )
}

/// The parts' values of one number pooled: inverse-variance weighted when every value has a
/// standard error (then with `χ²` about the pooled value), else their plain mean.
pub fn pool(per_part: Vec<Option<PartValue>>) -> PooledNumber {
    let values: Vec<PartValue> = per_part.iter().flatten().copied().collect();
    let weights: Option<Vec<f64>> = values
        .iter()
        .map(|v| v.standard_error.map(|s| 1.0 / (s * s)))
        .collect();
    let Some(weights) = weights else {
        let value = values.iter().map(|v| v.value).sum::<f64>() / values.len() as f64;
        return PooledNumber {
            value,
            standard_error: None,
            per_part,
            chi_square_per_dof: None,
            varies: false,
        };
    };
    let total: f64 = weights.iter().sum();
    let value = values
        .iter()
        .zip(&weights)
        .map(|(v, w)| w * v.value)
        .sum::<f64>()
        / total;
    let chi_square: f64 = values
        .iter()
        .zip(&weights)
        .map(|(v, w)| w * (v.value - value).powi(2))
        .sum();
    let dof = values.len().saturating_sub(1);
    let varies =
        dof > 0 && ChiSquared::new(dof as f64).is_ok_and(|d| d.cdf(chi_square) > VARIES_QUANTILE);
    PooledNumber {
        value,
        standard_error: Some(total.sqrt().recip()),
        per_part,
        chi_square_per_dof: (dof > 0).then(|| chi_square / dof as f64),
        varies,
    }
}

impl PartedAnalysis {
    /// What the summary shows, with the parts as [`Self::part_lines`] lists them.
    pub fn view<'a>(&'a self, lines: &'a [PartLine]) -> PartsView<'a> {
        PartsView {
            recording: &self.recording,
            model: &self.model,
            rows: self.rows,
            part_rows: self.part_rows,
            parts: lines,
            effects: &self.effects,
            heldout: Some(self.heldout),
        }
    }

    /// Each part as the summary lists it.
    pub fn part_lines(&self) -> Vec<PartLine> {
        self.parts
            .iter()
            .map(|part| PartLine {
                rows: part.rows,
                t_start: part.t_start,
                t_end: part.t_end,
                named: part
                    .report
                    .iter()
                    .flat_map(|r| &r.effects)
                    .map(|e| e.id.name().to_string())
                    .collect(),
                heldout: part
                    .report
                    .as_ref()
                    .map(|r| [r.fit.heldout.before.mse, r.fit.heldout.after.mse]),
                refused: part.refused.clone(),
            })
            .collect()
    }

    /// The contents of the files [`super::files::ANALYSIS_FILES`] names (`mismatch.json`,
    /// `mismatch.svg`, `mismatch.md`), to be written in `dir`.
    pub fn render(&self, dir: &Path) -> Result<[String; 3]> {
        let lines = self.part_lines();
        let view = self.view(&lines);
        let names = super::files::ANALYSIS_FILES;
        let json = serde_json::to_string_pretty(self).expect("the report serialises");
        let svg = view.svg(&dir.join(names[1]))?;
        Ok([json + "\n", svg, view.markdown(names[1])])
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parts_are_equal_consecutive_and_within_the_bound() {
        assert_eq!(part_ranges(1_000, 40_000), vec![0..1_000]);
        assert_eq!(part_ranges(40_000, 40_000), vec![0..40_000]);
        assert_eq!(part_ranges(40_001, 40_000), vec![0..20_000, 20_000..40_001]);
        for (rows, bound) in [(180_001, 40_000), (900_000, 40_000), (3_001, 1_500), (7, 3)] {
            let ranges = part_ranges(rows, bound);
            assert_eq!(ranges.len(), rows.div_ceil(bound), "{rows} by {bound}");
            assert_eq!(ranges[0].start, 0);
            assert_eq!(ranges.last().unwrap().end, rows);
            assert!(ranges.windows(2).all(|w| w[0].end == w[1].start));
            let (low, high) = (
                ranges.iter().map(|r| r.len()).min().unwrap(),
                ranges.iter().map(|r| r.len()).max().unwrap(),
            );
            assert!(
                high <= bound && high - low <= 1,
                "{rows} by {bound}: {low}..{high}"
            );
        }
    }

    fn value(value: f64, standard_error: f64) -> Option<PartValue> {
        Some(PartValue {
            value,
            standard_error: Some(standard_error),
        })
    }

    #[test]
    fn numbers_pool_by_inverse_variance_and_drift_is_flagged() {
        // Weights 4 and 1: (4·1 + 1·2) / 5 = 1.2, standard error 1/√5.
        let pooled = pool(vec![value(1.0, 0.5), None, value(2.0, 1.0)]);
        assert!((pooled.value - 1.2).abs() < 1e-12);
        assert!((pooled.standard_error.unwrap() - 5f64.sqrt().recip()).abs() < 1e-12);
        // χ² = 4·0.04 + 1·0.64 = 0.8 on one degree of freedom.
        assert!((pooled.chi_square_per_dof.unwrap() - 0.8).abs() < 1e-12);
        assert!(!pooled.varies);
        assert_eq!(pooled.per_part.len(), 3);
        // Six parts drifting by 10 standard errors each.
        let drifting = pool((0..6).map(|i| value(1.0 + 0.1 * i as f64, 0.01)).collect());
        assert!(drifting.varies && drifting.chi_square_per_dof.unwrap() > 100.0);
        let steady = pool(
            (0..6)
                .map(|i| value(1.0 + 0.001 * (i % 2) as f64, 0.01))
                .collect(),
        );
        assert!(!steady.varies);
        // One value has no error: the plain mean, nothing tested.
        let plain = pool(vec![
            value(1.0, 0.5),
            Some(PartValue {
                value: 2.0,
                standard_error: None,
            }),
        ]);
        assert_eq!(
            (plain.value, plain.standard_error, plain.varies),
            (1.5, None, false)
        );
    }
}
