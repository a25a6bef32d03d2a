//! Where the recording disagrees with the model: each channel's residual against its noise floor
//! and the time windows where its moving RMS rises above it.

use report::mismatch::recording::{ChannelReport, Window};

use crate::locate::problem::{CHANNEL_NAMES, Channels, Problem};
use crate::model::refine::{FitRows, StepBasis};
use crate::settings::LocateSettings;

/// The nominal and the fitted model's residuals.
pub(crate) struct Residuals<'a> {
    pub before: &'a [Channels],
    pub after: &'a [Channels],
}

/// Each channel's residual against its noise floor, before and after the fitted effects.
pub(crate) fn channel_reports(
    problem: &Problem,
    settings: &LocateSettings,
    residuals: &Residuals,
) -> Vec<ChannelReport> {
    let heldout_rows = problem.split..problem.rows();
    let channel_mse = |residual: &[Channels], c: usize| {
        residual[heldout_rows.clone()]
            .iter()
            .map(|r| r[c] * r[c])
            .sum::<f64>()
            / heldout_rows.len().max(1) as f64
    };
    let fit_rows = 0..problem.split;
    (0..problem.channels)
        .map(|c| {
            let floor = problem.noise_floor[c];
            let nominal = fit_rows
                .clone()
                .map(|row| problem.target[row][c] - residuals.before[row][c]);
            let signal_variance = variance(nominal);
            let model_noise_share = if signal_variance > 0.0 {
                problem.model_noise[c].powi(2) / signal_variance
            } else {
                0.0
            };
            let residual_rms = rms(residuals.before.iter().map(|r| r[c]));
            let residual_rms_after = rms(residuals.after.iter().map(|r| r[c]));
            ChannelReport {
                name: CHANNEL_NAMES[c].to_string(),
                residual_rms,
                noise_floor: floor,
                noise_floor_model_side: problem.model_noise[c],
                model_noise_share,
                significant: residual_rms > settings.significance_factor * floor,
                residual_rms_after,
                significant_after: residual_rms_after > settings.significance_factor * floor,
                heldout_mse_before: channel_mse(residuals.before, c),
                heldout_mse_after: channel_mse(residuals.after, c),
            }
        })
        .collect()
}

/// `residual` (all rows) without its components along the test functions' values at the command
/// steps the samples cannot place: a step misplaced within its interval is not a missing effect.
pub(crate) fn without_steps(
    problem: &Problem,
    residual: &[Channels],
    step_times: &[f64],
) -> Vec<Channels> {
    let mut remaining = residual.to_vec();
    StepBasis::new(problem, &FitRows::plain(0..problem.rows()), step_times)
        .remove_from(&mut remaining);
    remaining
}

/// Windows where the centred moving RMS of a channel's residual exceeds `factor` × floor.
pub(crate) fn locate_windows(
    problem: &Problem,
    residual: &[Channels],
    settings: &LocateSettings,
) -> Vec<Window> {
    let rows = residual.len();
    let half = half_window_rows(settings.window_s, problem.recording.dt(), rows);
    let mut windows = Vec::new();
    for c in 0..problem.channels {
        let threshold = (settings.window_factor * problem.noise_floor[c]).powi(2);
        let squares: Vec<f64> = residual.iter().map(|r| r[c] * r[c]).collect();
        let mut prefix = vec![0.0; rows + 1];
        for k in 0..rows {
            prefix[k + 1] = prefix[k] + squares[k];
        }
        let flagged: Vec<bool> = (0..rows)
            .map(|k| {
                let (a, b) = (k.saturating_sub(half), (k + half + 1).min(rows));
                (prefix[b] - prefix[a]) / (b - a) as f64 > threshold
            })
            .collect();
        let mut k = 0;
        while k < rows {
            if !flagged[k] {
                k += 1;
                continue;
            }
            let start = k;
            while k < rows && flagged[k] {
                k += 1;
            }
            let (t_start, t_end) = (problem.time[start], problem.time[k - 1]);
            if t_end - t_start >= settings.min_window_s {
                windows.push(Window {
                    channel: CHANNEL_NAMES[c].to_string(),
                    t_start,
                    t_end,
                });
            }
        }
    }
    windows
}

/// Half the length, in rows, of a moving window of `window_s` seconds at sample interval `dt`,
/// capped at `rows` (a window longer than the recording is the whole recording), so that the
/// window's row arithmetic cannot overflow however small `dt` is.
fn half_window_rows(window_s: f64, dt: f64, rows: usize) -> usize {
    (((window_s / dt) / 2.0).round() as usize).min(rows)
}

fn rms(values: impl Iterator<Item = f64>) -> f64 {
    let (sum, count) = values.fold((0.0, 0usize), |(s, n), v| (s + v * v, n + 1));
    (sum / count.max(1) as f64).sqrt()
}

/// The variance of a series about its mean (0 for fewer than two values).
fn variance(values: impl Iterator<Item = f64>) -> f64 {
    let values: Vec<f64> = values.collect();
    if values.len() < 2 {
        return 0.0;
    }
    let mean = values.iter().sum::<f64>() / values.len() as f64;
    values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / values.len() as f64
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_moving_window_cannot_overflow() {
        // 1 s at 50 Hz: 25 rows either side, as before.
        assert_eq!(half_window_rows(1.0, 0.02, 2500), 25);
        // Times × 1e-300: the window would be ~1e300 rows; capped at the recording.
        let rows = 2000;
        let half = half_window_rows(1.0, 2e-302, rows);
        assert_eq!(half, rows);
        let k = rows - 1;
        assert_eq!(
            (k.saturating_sub(half), (k + half + 1).min(rows)),
            (0, rows)
        );
        // A NaN interval gives a zero-row window, not a panic.
        assert_eq!(half_window_rows(1.0, f64::NAN, rows), 0);
    }
}
