//! What the logs allow on the angular channels when the nominal model has no torques (its thrust
//! comes from `T_sp`): how the motor commands relate to the thrust setpoint, and how much of the
//! body's angular acceleration a torque map from the motor commands explains, identified on
//! the calm flights and checked where it was not fitted. Nothing is named in the angular channels
//! unless such a map explains most of them.

use faer::Mat;
use faer::linalg::solvers::Solve;
use report::mismatch::fleet::AttitudeCheck;

use super::FleetFlight;

/// The largest lag of the motor commands behind the body's response tried, rows.
const MAX_LAG_ROWS: usize = 6;

/// Per flight and row: the weak-form target of the body rate, and the weak form of the lagged
/// motor commands (one per motor).
fn regressors(flight: &FleetFlight, lag: usize) -> (Vec<[f64; 3]>, Vec<Vec<f64>>) {
    let problem = &flight.problem;
    let form = &problem.weak_form;
    let rate = &problem.recording.body_rate;
    let mut target = vec![[0.0; 3]; problem.rows()];
    for c in 0..3 {
        let signal: Vec<f64> = rate.iter().map(|w| w[c]).collect();
        for (row, value) in target.iter_mut().zip(form.target(&signal)) {
            row[c] = value;
        }
    }
    let pwm = &flight.pwm;
    let motors = pwm.count();
    let lagged: Vec<Vec<f64>> = (0..pwm.len())
        .map(|k| {
            pwm.row(k.saturating_sub(lag))
                .iter()
                .map(|v| v / 100.0)
                .collect()
        })
        .collect();
    let mut commands = vec![vec![0.0; motors]; problem.rows()];
    // Three motors at a time (the weak form integrates triples), the last triple ending at the
    // last motor: for four, motors 0–2 and 1–3.
    for start in (0..motors).step_by(3) {
        let triple = std::array::from_fn::<usize, 3, _>(|k| {
            (start.min(motors.saturating_sub(3)) + k).min(motors - 1)
        });
        let three: Vec<[f64; 3]> = lagged.iter().map(|p| triple.map(|i| p[i])).collect();
        for (row, value) in commands.iter_mut().zip(form.integrate_rows(&three)) {
            for (k, &i) in triple.iter().enumerate() {
                row[i] = value[k];
            }
        }
    }
    (target, commands)
}

/// One flight's weak-form angular acceleration and motor commands, with the rows to use.
type Sample = (Vec<[f64; 3]>, Vec<Vec<f64>>, std::ops::Range<usize>);

/// Least squares of `y = c + B u` per axis on the given rows, `u` the `motors` commands; returns
/// the coefficients per axis (constant first).
fn fit_map(samples: &[Sample], motors: usize) -> [Vec<f64>; 3] {
    let size = motors + 1;
    let mut gram = Mat::<f64>::zeros(size, size);
    let mut cross = Mat::<f64>::zeros(size, 3);
    let mut x = vec![1.0; size];
    for (target, commands, rows) in samples {
        for r in rows.clone() {
            x[1..].copy_from_slice(&commands[r]);
            for i in 0..size {
                for j in 0..size {
                    gram[(i, j)] += x[i] * x[j];
                }
                for c in 0..3 {
                    cross[(i, c)] += x[i] * target[r][c];
                }
            }
        }
    }
    for i in 0..size {
        gram[(i, i)] += 1e-9 * (1.0 + gram[(i, i)]);
    }
    let solution = gram.full_piv_lu().solve(&cross);
    std::array::from_fn(|c| (0..size).map(|i| solution[(i, c)]).collect())
}

/// `1 − SSE / SST` per axis (SST about the mean) of the map on the given rows.
fn explained(samples: &[Sample], map: &[Vec<f64>; 3]) -> [f64; 3] {
    let mut out = [0.0; 3];
    for c in 0..3 {
        let values: Vec<(f64, f64)> = samples
            .iter()
            .flat_map(|(target, commands, rows)| {
                rows.clone().map(move |r| {
                    let u = &commands[r];
                    let predicted =
                        map[c][0] + (0..u.len()).map(|i| map[c][i + 1] * u[i]).sum::<f64>();
                    (target[r][c], predicted)
                })
            })
            .collect();
        let n = values.len().max(1) as f64;
        let mean = values.iter().map(|v| v.0).sum::<f64>() / n;
        let total: f64 = values.iter().map(|v| (v.0 - mean).powi(2)).sum();
        let error: f64 = values.iter().map(|v| (v.0 - v.1).powi(2)).sum();
        out[c] = 1.0 - error / total.max(1e-300);
    }
    out
}

/// The mean motor command against `T_sp`: offset, slope, the lag that fits best and its residual
/// RMS, over every flight.
fn mean_pwm_law(flights: &[FleetFlight]) -> (f64, f64, usize, f64) {
    let mut best = (0.0, 0.0, 0, f64::INFINITY);
    for lag in 0..=MAX_LAG_ROWS {
        let pairs: Vec<(f64, f64)> = flights
            .iter()
            .flat_map(|f| {
                let (n, motors) = (f.pwm.len(), f.pwm.count() as f64);
                (lag..n).map(move |k| {
                    (
                        f.thrust_setpoint[k - lag],
                        f.pwm.row(k).iter().sum::<f64>() / motors,
                    )
                })
            })
            .collect();
        let n = pairs.len().max(1) as f64;
        let (mx, my) = pairs
            .iter()
            .fold((0.0, 0.0), |(a, b), (x, y)| (a + x / n, b + y / n));
        let sxx: f64 = pairs.iter().map(|(x, _)| (x - mx).powi(2)).sum();
        let sxy: f64 = pairs.iter().map(|(x, y)| (x - mx) * (y - my)).sum();
        let slope = sxy / sxx.max(1e-300);
        let offset = my - slope * mx;
        let rms = (pairs
            .iter()
            .map(|(x, y)| (y - offset - slope * x).powi(2))
            .sum::<f64>()
            / n)
            .sqrt();
        if rms < best.3 {
            best = (offset, slope, lag, rms);
        }
    }
    best
}

/// The attitude check over the flights (calm ones identify, windy ones only check).
pub fn check(flights: &[FleetFlight]) -> Option<AttitudeCheck> {
    let motors = flights.first()?.pwm.count();
    if flights.iter().all(|f| !f.calm) || flights.iter().any(|f| f.pwm.count() != motors) {
        return None;
    }
    let (lo, hi) = flights
        .iter()
        .flat_map(|f| f.pwm.rows().flatten())
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
            (a.min(*v), b.max(*v))
        });
    let (offset, slope, pwm_lag, pwm_rms) = mean_pwm_law(flights);
    let samples_at = |lag: usize, calm: bool, part: fn(&FleetFlight) -> std::ops::Range<usize>| {
        flights
            .iter()
            .filter(|f| f.calm == calm)
            .map(|f| {
                let (target, commands) = regressors(f, lag);
                (target, commands, part(f))
            })
            .collect::<Vec<_>>()
    };
    let fit_part = |f: &FleetFlight| 0..f.problem.split;
    let heldout_part = |f: &FleetFlight| f.problem.split..f.problem.rows();
    let all_rows = |f: &FleetFlight| 0..f.problem.rows();
    let (lag, map, calm_heldout) = (0..=MAX_LAG_ROWS)
        .map(|lag| {
            let map = fit_map(&samples_at(lag, true, fit_part), motors);
            let score = explained(&samples_at(lag, true, heldout_part), &map);
            (lag, map, score)
        })
        .max_by(|a, b| {
            let sum = |s: &[f64; 3]| s.iter().sum::<f64>();
            sum(&a.2).total_cmp(&sum(&b.2))
        })?;
    let windy = samples_at(lag, false, all_rows);
    let explained_windy = (!windy.is_empty()).then(|| explained(&windy, &map));
    Some(AttitudeCheck {
        pwm_range: [lo, hi],
        mean_pwm_offset: offset,
        mean_pwm_slope: slope,
        mean_pwm_lag_rows: pwm_lag,
        mean_pwm_lag_s: pwm_lag as f64 * flights[0].problem.recording.dt(),
        mean_pwm_residual_rms: pwm_rms,
        torque_map_lag_rows: lag,
        explained_calm_heldout: calm_heldout,
        explained_windy,
    })
}
