//! The samples a sampled command is reconstructed through, and the actuator limits the log shows.
//!
//! A mixer turns the controller's wrench into per-rotor thrusts, linear in the wrench and smooth
//! when it is; the speeds it commands are their square roots, which bend sharply where a thrust
//! nears zero. A rotor at a limit holds one command while the demand behind it goes beyond. So a
//! logged speed is reconstructed through its per-rotor thrust, the squared speed the model's mixer
//! is linear in ([`SampleDomain::SquaredSpeed`]), and a run of samples held at a limit is first
//! replaced by the smoothest continuation of its neighbours (least third differences) beyond the
//! limit; the curve through the samples is then clipped to the limits, as the rotor clipped the
//! demand. Commands held or averaged over the log period are used as logged
//! ([`crate::locate::forward`]).

use faer::Mat;
use faer::linalg::solvers::Solve;
use physics::{Actuators, MAX_ACTUATORS, NominalModel, ThrustSource};
use serde::Serialize;

/// A value held on at least this many rows, at the extreme of its column, is an actuator limit
/// (a smooth signal does not repeat its extreme exactly).
pub const MIN_ROWS_AT_LIMIT: usize = 3;
/// Known samples on each side of a run at a limit that its continuation is fitted to.
const PAD: usize = 4;
/// The longest run solved as one; a longer run is continued from each end over this many samples.
const MAX_RUN: usize = 64;

/// The quantity a sampled command is interpolated in.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum SampleDomain {
    /// The logged command itself (a collective-thrust setpoint).
    Command,
    /// The square of a normalised motor speed: the per-rotor thrust a mixer is linear in.
    SquaredSpeed,
}

impl SampleDomain {
    /// The domain of a model's actuator commands.
    pub fn of(model: &NominalModel) -> Self {
        match model.thrust_source {
            ThrustSource::Mixer => Self::SquaredSpeed,
            ThrustSource::ThrustSetpoint => Self::Command,
        }
    }

    /// A command's value in the domain.
    pub fn to_domain(self, command: f64) -> f64 {
        match self {
            Self::Command => command,
            Self::SquaredSpeed => command.max(0.0).powi(2),
        }
    }

    /// A value in the domain as a command.
    pub fn to_command(self, value: f64) -> f64 {
        match self {
            Self::Command => value,
            Self::SquaredSpeed => value.max(0.0).sqrt(),
        }
    }
}

/// The limits one actuator's logged command sits at (in the command's units), with how many rows
/// sit there.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct ActuatorLimits {
    #[serde(skip_serializing_if = "Option::is_none")]
    pub lower: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub upper: Option<f64>,
    pub rows_at_limit: usize,
}

/// Where a logged sample sits: inside the range, or held at a limit.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Held {
    Inside,
    Lower,
    Upper,
}

/// The limits of the first `count` actuators: an extreme of a column held on at least
/// [`MIN_ROWS_AT_LIMIT`] rows (none for a constant column).
pub fn detect_limits(commands: &[Actuators], count: usize) -> [ActuatorLimits; MAX_ACTUATORS] {
    let mut limits = [ActuatorLimits::default(); MAX_ACTUATORS];
    for (i, limit) in limits.iter_mut().enumerate().take(count) {
        let column = || commands.iter().map(|c| c[i]);
        let low = column().fold(f64::INFINITY, f64::min);
        let high = column().fold(f64::NEG_INFINITY, f64::max);
        if !(low.is_finite() && high.is_finite() && high > low) {
            continue;
        }
        let at = |value: f64| column().filter(|&c| c == value).count();
        let (at_low, at_high) = (at(low), at(high));
        if at_low >= MIN_ROWS_AT_LIMIT {
            limit.lower = Some(low);
            limit.rows_at_limit += at_low;
        }
        if at_high >= MIN_ROWS_AT_LIMIT {
            limit.upper = Some(high);
            limit.rows_at_limit += at_high;
        }
    }
    limits
}

/// A command step stands out of the sample-to-sample changes by more than this many robust
/// standard deviations ([`CommandSamples::unplaced_steps`]).
pub const STEP_SIGMAS: f64 = 5.0;

/// The samples of a recording's commands in the domain they are interpolated in, runs at a limit
/// continued beyond it, and the limits in that domain.
#[derive(Clone, Debug)]
pub struct CommandSamples {
    pub values: Vec<Actuators>,
    pub count: usize,
    pub domain: SampleDomain,
    /// Per actuator, the range the reconstruction is clipped to (in the domain).
    pub range: [(f64, f64); MAX_ACTUATORS],
    /// Per row and actuator, whether the logged sample was held at a limit.
    held: Vec<[Held; MAX_ACTUATORS]>,
    /// Whether the values are instantaneous samples (so a step between two says nothing of when).
    sampled: bool,
}

impl CommandSamples {
    /// The commands as they are, without limits (commands held or averaged over the log period).
    pub fn plain(commands: &[Actuators], count: usize) -> Self {
        Self {
            values: commands.to_vec(),
            count,
            domain: SampleDomain::Command,
            range: [(f64::NEG_INFINITY, f64::INFINITY); MAX_ACTUATORS],
            held: vec![[Held::Inside; MAX_ACTUATORS]; commands.len()],
            sampled: false,
        }
    }

    /// The samples of the logged commands in `domain`, those held at a limit continued beyond it.
    pub fn new(
        logged: &[Actuators],
        count: usize,
        domain: SampleDomain,
        limits: &[ActuatorLimits; MAX_ACTUATORS],
    ) -> Self {
        let mut range = [(f64::NEG_INFINITY, f64::INFINITY); MAX_ACTUATORS];
        for i in 0..count {
            let floor = if domain == SampleDomain::SquaredSpeed {
                0.0
            } else {
                f64::NEG_INFINITY
            };
            range[i] = (
                limits[i].lower.map_or(floor, |l| domain.to_domain(l)),
                limits[i]
                    .upper
                    .map_or(f64::INFINITY, |u| domain.to_domain(u)),
            );
        }
        let held = logged
            .iter()
            .map(|c| {
                std::array::from_fn(|i| match (limits[i].lower, limits[i].upper) {
                    _ if i >= count => Held::Inside,
                    (Some(l), _) if c[i] == l => Held::Lower,
                    (_, Some(u)) if c[i] == u => Held::Upper,
                    _ => Held::Inside,
                })
            })
            .collect();
        let samples = Self {
            values: Vec::new(),
            count,
            domain,
            range,
            held,
            sampled: true,
        };
        samples.with_commands(logged)
    }

    /// The same limits and held samples with other values of the commands (corrected ones): the
    /// samples held at a limit are continued from the new values around them.
    pub fn with_commands(&self, commands: &[Actuators]) -> Self {
        let mut values: Vec<Actuators> = commands
            .iter()
            .map(|c| c.map(|v| self.domain.to_domain(v)))
            .collect();
        for i in 0..self.count {
            let held: Vec<Held> = self.held.iter().map(|h| h[i]).collect();
            if held.iter().all(|h| *h == Held::Inside) {
                continue;
            }
            let mut column: Vec<f64> = values.iter().map(|v| v[i]).collect();
            continue_runs(&mut column, &held, self.range[i]);
            for (v, c) in values.iter_mut().zip(column) {
                v[i] = c;
            }
        }
        Self {
            values,
            count: self.count,
            domain: self.domain,
            range: self.range,
            held: self.held.clone(),
            sampled: self.sampled,
        }
    }

    /// The intervals `k` (between rows `k` and `k + 1`) in which an instantaneous sample's command
    /// steps: some actuator's change over the interval departs from the mean of its neighbours'
    /// changes by more than [`STEP_SIGMAS`] robust standard deviations of that departure. No
    /// sample says when within the interval the step came, so the curve through the samples
    /// misplaces it by up to half a row. Empty for commands held or averaged over the log period.
    pub fn unplaced_steps(&self) -> Vec<usize> {
        let n = self.values.len();
        if !self.sampled || n < 4 {
            return Vec::new();
        }
        let mut steps = vec![false; n - 1];
        for i in 0..self.count {
            let departure: Vec<f64> = (1..n - 2)
                .map(|k| {
                    let change = |j: usize| self.values[j + 1][i] - self.values[j][i];
                    change(k) - 0.5 * (change(k - 1) + change(k + 1))
                })
                .collect();
            let magnitude = self.values.iter().map(|v| v[i].abs()).fold(0.0, f64::max);
            let scale = sindy::median::robust_standard_deviation(departure.iter().copied())
                .max(1e-9 * magnitude);
            for (k, d) in departure.iter().enumerate() {
                let inside = (k..k + 4).all(|j| self.held[j][i] == Held::Inside);
                if inside && d.abs() > STEP_SIGMAS * scale {
                    steps[k + 1] = true;
                }
            }
        }
        steps
            .iter()
            .enumerate()
            .filter(|(_, s)| **s)
            .map(|(k, _)| k)
            .collect()
    }

    /// The rows whose logged command was held at a limit by some actuator.
    pub fn rows_held(&self) -> usize {
        self.held
            .iter()
            .filter(|h| h.iter().any(|&x| x != Held::Inside))
            .count()
    }

    /// A value interpolated between samples, back in the command's units: clipped to the range
    /// first, as the actuator clipped the demand.
    pub fn command(&self, actuator: usize, value: f64) -> f64 {
        let (low, high) = self.range[actuator];
        self.domain.to_command(value.max(low).min(high))
    }

    /// [`CommandSamples::command`] of every actuator of an interpolated value (the others kept).
    pub fn commands(&self, mut values: Actuators) -> Actuators {
        for (i, value) in values.iter_mut().enumerate().take(self.count) {
            *value = self.command(i, *value);
        }
        values
    }
}

/// Replaces each run of samples held at a limit by the continuation of its neighbours that
/// minimises the sum of squared third differences, kept beyond the limit.
fn continue_runs(column: &mut [f64], held: &[Held], (low, high): (f64, f64)) {
    let n = column.len();
    let mut k = 0;
    while k < n {
        if held[k] == Held::Inside {
            k += 1;
            continue;
        }
        let side = held[k];
        let start = k;
        while k < n && held[k] == side {
            k += 1;
        }
        let beyond = |v: f64| match side {
            Held::Lower => v.min(low),
            _ => v.max(high),
        };
        if k - start <= MAX_RUN {
            continue_segment(column, start, k, beyond);
        } else {
            continue_segment(column, start, start + MAX_RUN / 2, beyond);
            continue_segment(column, k - MAX_RUN / 2, k, beyond);
            // The middle is far from any sample inside the range: as extreme as its ends.
            let fill = match side {
                Held::Lower => column[start + MAX_RUN / 2 - 1].min(column[k - MAX_RUN / 2]),
                _ => column[start + MAX_RUN / 2 - 1].max(column[k - MAX_RUN / 2]),
            };
            column[start + MAX_RUN / 2..k - MAX_RUN / 2].fill(fill);
        }
    }
}

/// Third-difference weights.
const THIRD_DIFFERENCE: [f64; 4] = [-1.0, 3.0, -3.0, 1.0];

/// The unknowns `[start, end)` of `column` that minimise the squared third differences over the
/// segment with [`PAD`] samples on each side, mapped by `beyond`; left as they are when the segment
/// is too short to determine them.
fn continue_segment(column: &mut [f64], start: usize, end: usize, beyond: impl Fn(f64) -> f64) {
    let first = start.saturating_sub(PAD);
    let last = (end + PAD).min(column.len());
    let unknowns = end - start;
    let order = THIRD_DIFFERENCE.len() - 1;
    if last - first < unknowns + order || unknowns == 0 {
        return;
    }
    let mut normal = Mat::<f64>::zeros(unknowns, unknowns);
    let mut right = Mat::<f64>::zeros(unknowns, 1);
    for row in first..last - order {
        let mut known = 0.0;
        let mut terms = [(0usize, 0.0f64); 4];
        let mut count = 0;
        for (m, weight) in THIRD_DIFFERENCE.iter().enumerate() {
            let index = row + m;
            if (start..end).contains(&index) {
                terms[count] = (index - start, *weight);
                count += 1;
            } else {
                known += weight * column[index];
            }
        }
        for &(p, wp) in &terms[..count] {
            right[(p, 0)] -= wp * known;
            for &(q, wq) in &terms[..count] {
                normal[(p, q)] += wp * wq;
            }
        }
    }
    let solution = normal.full_piv_lu().solve(&right);
    for u in 0..unknowns {
        let value = solution[(u, 0)];
        if value.is_finite() {
            column[start + u] = beyond(value);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use physics::actuators;

    #[test]
    fn a_repeated_extreme_is_a_limit_and_a_smooth_extreme_is_not() {
        let smooth: Vec<Actuators> = (0..200)
            .map(|k| actuators(&[(k as f64 * 0.1).sin(), 0.5]))
            .collect();
        let limits = detect_limits(&smooth, 2);
        assert_eq!(limits[0], ActuatorLimits::default());
        assert_eq!(limits[1], ActuatorLimits::default(), "a constant column");
        let clipped: Vec<Actuators> = smooth
            .iter()
            .map(|c| actuators(&[c[0].clamp(-0.8, 0.9)]))
            .collect();
        let limits = detect_limits(&clipped, 1);
        assert_eq!((limits[0].lower, limits[0].upper), (Some(-0.8), Some(0.9)));
        assert!(limits[0].rows_at_limit > 20);
    }

    /// A demand that dips below zero, logged as speeds clipped at zero: continued through its
    /// squares, the dip is recovered beyond the limit (the squared speeds are a parabola here, which
    /// least third differences continue exactly).
    #[test]
    fn a_run_at_a_limit_is_continued_beyond_it() {
        let demand = |k: usize| 0.04 * (k as f64 - 20.0).powi(2) - 1.0;
        let logged: Vec<Actuators> = (0..40)
            .map(|k| actuators(&[demand(k).max(0.0).sqrt()]))
            .collect();
        let limits = detect_limits(&logged, 1);
        assert_eq!(limits[0].lower, Some(0.0));
        let samples = CommandSamples::new(&logged, 1, SampleDomain::SquaredSpeed, &limits);
        for k in 16..25 {
            assert!((samples.values[k][0] - demand(k)).abs() < 1e-9, "row {k}");
        }
        assert_eq!(samples.command(0, -0.3), 0.0);
        assert!((samples.command(0, 0.25) - 0.5).abs() < 1e-12);
    }

    /// A smooth command with white noise and one step between rows 120 and 121: the step's
    /// interval is found, nothing else is, and commands held or averaged over the log period have
    /// no unplaced step.
    #[test]
    fn a_command_step_between_samples_is_found() {
        use rand::SeedableRng;
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(5);
        let mut noise = || crate::improve::simex::gaussian(&mut rng, 0.01);
        let logged: Vec<Actuators> = (0..300)
            .map(|k| {
                let step = if k > 120 { 0.3 } else { 0.0 };
                let smooth = 0.5 + 0.2 * (k as f64 * 0.05).sin();
                actuators(&[smooth + step + noise(), 0.5])
            })
            .collect();
        let limits = detect_limits(&logged, 2);
        let samples = CommandSamples::new(&logged, 2, SampleDomain::Command, &limits);
        let steps = samples.unplaced_steps();
        assert!(steps.contains(&120), "{steps:?}");
        assert!(steps.iter().all(|k| (119..=121).contains(k)), "{steps:?}");
        assert!(
            CommandSamples::plain(&logged, 2)
                .unplaced_steps()
                .is_empty()
        );
    }
}
