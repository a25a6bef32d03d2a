//! The model's acceleration on a fine grid between the rows, with any set of effects.
//!
//! The command the vehicle received is reconstructed from the logged one as the model's logger
//! says ([`physics::Logger`]): a windowed-sinc (Lanczos) curve through instantaneous samples (half a
//! control period late when the controller's rate is known: each command is held until the next), or a
//! command constant over each log period (held from its row to the next, or the mean over the period
//! before its row), shifted by the logger's time offset. A delay shifts it further and a motor lag
//! filters it (exactly, for a command constant over each sub-interval). Attitude, velocity, position
//! and rate are interpolated linearly between the rows. With a body-rate filter in the logger, the
//! angular acceleration goes through the same first-order filter, as the logged rate did.

use physics::vector::{Mat3, Vec3};
use physics::{Actuators, CommandLogging, Effects, Logger, MAX_ACTUATORS, NominalModel, Wrench};

use sindy::sampling::Sampling;

use crate::recording::Recording;
use crate::recording::command_samples::CommandSamples;

/// Sub-intervals per sample interval.
pub const SUBSTEPS: usize = 10;

/// The accelerations at the midpoints of every sub-interval (`(n − 1) · SUBSTEPS` of each).
#[derive(Clone, Debug)]
pub struct SubstepPrediction {
    pub translational: Vec<Vec3>,
    /// When the model predicts torques.
    pub angular: Option<Vec<Vec3>>,
}

/// Predicts the accelerations of a recording on the fine grid.
pub fn predict_substeps(
    recording: &Recording,
    model: &NominalModel,
    effects: &Effects,
) -> SubstepPrediction {
    predict_substeps_with(
        recording,
        model,
        effects,
        &WrenchTrace::new(recording, model, effects),
    )
}

/// The model's thrust and torques at every sub-interval midpoint, from the commands reconstructed
/// with one delay and motor lag: what a prediction takes from the commands, the same for every
/// set of effects with that timing (a search over other parameters computes it once).
#[derive(Clone, Debug)]
pub struct WrenchTrace {
    delay_s: f64,
    lag_s: f64,
    wrenches: Vec<Wrench>,
}

impl WrenchTrace {
    /// The trace for the delay and motor lag of `effects`.
    pub fn new(recording: &Recording, model: &NominalModel, effects: &Effects) -> Self {
        let (delay_s, lag_s) = (effects.delay_s(), effects.lag_s());
        let actuators = actuator_trace(
            &recording.samples,
            &recording.sampling,
            &model.logger,
            delay_s,
            lag_s,
        );
        let spread = spread_after_lag(recording, lag_s);
        let wrenches = actuators
            .iter()
            .map(|a| model.wrench_with_spread(a, &spread))
            .collect();
        Self {
            delay_s,
            lag_s,
            wrenches,
        }
    }

    /// Whether `effects` have the timing this trace was made with.
    pub fn serves(&self, effects: &Effects) -> bool {
        self.delay_s.to_bits() == effects.delay_s().to_bits()
            && self.lag_s.to_bits() == effects.lag_s().to_bits()
    }
}

/// [`predict_substeps`] with the commands' wrench already traced for the effects' timing.
pub fn predict_substeps_with(
    recording: &Recording,
    model: &NominalModel,
    effects: &Effects,
    wrenches: &WrenchTrace,
) -> SubstepPrediction {
    assert!(
        wrenches.serves(effects),
        "a wrench trace serves only effects with its delay and motor lag"
    );
    let n = recording.len();
    let angular_wanted = model.predicts_torque();
    let total = (n - 1) * SUBSTEPS;
    assert_eq!(
        wrenches.wrenches.len(),
        total,
        "a wrench trace of this recording"
    );
    let air_velocity = air_velocity_trace(recording, effects.drag_lag_s());
    let mut translational = Vec::with_capacity(total);
    let mut angular = Vec::with_capacity(if angular_wanted { total } else { 0 });
    for k in 0..n - 1 {
        for j in 0..SUBSTEPS {
            let s = (j as f64 + 0.5) / SUBSTEPS as f64;
            let rotation = lerp_matrix(&recording.rotation[k], &recording.rotation[k + 1], s);
            let velocity = match &air_velocity {
                Some(lagged) => lagged[k * SUBSTEPS + j],
                None => lerp(recording.velocity[k], recording.velocity[k + 1], s),
            };
            let position = lerp(recording.position[k], recording.position[k + 1], s);
            let wrench = &wrenches.wrenches[k * SUBSTEPS + j];
            let air_body = effects.body_airspeed(&rotation, velocity, position);
            translational.push(effects.translational_acceleration_in_air(
                model,
                &rotation,
                velocity,
                position,
                air_body,
                wrench.thrust,
            ));
            if angular_wanted {
                let rate = lerp(recording.body_rate[k], recording.body_rate[k + 1], s);
                let torque = wrench.torque.unwrap_or([0.0; 3]);
                angular.push(effects.angular_acceleration(model, rate, torque, air_body));
            }
        }
    }
    let tau = model.logger.rate_time_constant_s();
    if angular_wanted && tau > 0.0 {
        low_pass(&mut angular, &recording.sampling, tau);
    }
    SubstepPrediction {
        translational,
        angular: angular_wanted.then_some(angular),
    }
}

/// With a drag lag, the velocity the air terms see at every sub-interval midpoint: the linearly
/// interpolated velocity through a first-order lag of time constant `lag` (from the row's velocity
/// at the first row and after every gap).
fn air_velocity_trace(recording: &Recording, lag: f64) -> Option<Vec<Vec3>> {
    if lag <= 0.0 {
        return None;
    }
    let n = recording.len();
    let sampling = &recording.sampling;
    let mut gain = 1.0 - (-sampling.interval() / SUBSTEPS as f64 / lag).exp();
    let mut state = recording.velocity[0];
    let mut out = Vec::with_capacity((n - 1) * SUBSTEPS);
    for k in 0..n - 1 {
        if !sampling.is_uniform() {
            gain = 1.0 - (-sampling.interval_at(k) / SUBSTEPS as f64 / lag).exp();
            if segment_starts_at(sampling, k) {
                state = recording.velocity[k];
            }
        }
        for j in 0..SUBSTEPS {
            let s = (j as f64 + 0.5) / SUBSTEPS as f64;
            let velocity = lerp(recording.velocity[k], recording.velocity[k + 1], s);
            for i in 0..3 {
                state[i] += gain * (velocity[i] - state[i]);
            }
            out.push(state);
        }
    }
    Some(out)
}

/// Whether interval `k` is the first of a segment after a gap (the filters start afresh there, as
/// at the first row).
fn segment_starts_at(sampling: &Sampling, k: usize) -> bool {
    k > 0 && sampling.is_gap(k - 1)
}

/// The within-row spread of the commands that reaches the actuators: a first-order lag of time
/// constant `lag` passes `(1 − a) / (1 + a)` of white noise's variance at the command rate
/// (`a = e^(−h/lag)`, `h` the command period).
fn spread_after_lag(recording: &Recording, lag: f64) -> Actuators {
    match recording.command_rate_hz {
        Some(rate) if lag > 0.0 => {
            let a = (-1.0 / (rate * lag)).exp();
            recording.command_spread.map(|v| v * (1.0 - a) / (1.0 + a))
        }
        _ => recording.command_spread,
    }
}

/// Translational and (with torques) angular accelerations, one per row.
pub type RowPrediction = (Vec<Vec3>, Option<Vec<Vec3>>);

/// The nominal model's accelerations at the rows themselves, from each row's logged command and
/// measured state (translational, and angular when the model predicts torques).
pub fn predict_at_rows(recording: &Recording, model: &NominalModel) -> RowPrediction {
    accelerations_at_rows(recording, &recording.commands, model, &Effects::default())
}

/// The model's accelerations with `effects` at the rows themselves, from each row's command in
/// `commands` and the row's measured state.
pub fn accelerations_at_rows(
    recording: &Recording,
    commands: &[Actuators],
    model: &NominalModel,
    effects: &Effects,
) -> RowPrediction {
    let mut translational = Vec::with_capacity(recording.len());
    let mut angular = Vec::with_capacity(recording.len());
    for k in 0..recording.len() {
        let wrench = model.wrench(&commands[k]);
        let (rotation, velocity, position) = (
            &recording.rotation[k],
            recording.velocity[k],
            recording.position[k],
        );
        let air_body = effects.body_airspeed(rotation, velocity, position);
        translational.push(effects.translational_acceleration_in_air(
            model,
            rotation,
            velocity,
            position,
            air_body,
            wrench.thrust,
        ));
        if let Some(torque) = wrench.torque {
            angular.push(effects.angular_acceleration(
                model,
                recording.body_rate[k],
                torque,
                air_body,
            ));
        }
    }
    let angular = model.predicts_torque().then_some(angular);
    (translational, angular)
}

/// First-order low-pass of time constant `tau`, in place, over a series given at the sub-interval
/// midpoints of `sampling`, starting at the first value (and afresh after every gap).
fn low_pass(series: &mut [Vec3], sampling: &Sampling, tau: f64) {
    let mut gain = 1.0 - (-(sampling.interval() / SUBSTEPS as f64) / tau).exp();
    let mut state = series.first().copied().unwrap_or([0.0; 3]);
    for (index, value) in series.iter_mut().enumerate() {
        let (k, j) = (index / SUBSTEPS, index % SUBSTEPS);
        if !sampling.is_uniform() && j == 0 {
            gain = 1.0 - (-(sampling.interval_at(k) / SUBSTEPS as f64) / tau).exp();
            if segment_starts_at(sampling, k) {
                state = *value;
            }
        }
        for i in 0..3 {
            state[i] += gain * (value[i] - state[i]);
        }
        *value = state;
    }
}

fn lerp(a: Vec3, b: Vec3, s: f64) -> Vec3 {
    [
        a[0] + s * (b[0] - a[0]),
        a[1] + s * (b[1] - a[1]),
        a[2] + s * (b[2] - a[2]),
    ]
}

fn lerp_matrix(a: &Mat3, b: &Mat3, s: f64) -> Mat3 {
    [
        lerp(a[0], b[0], s),
        lerp(a[1], b[1], s),
        lerp(a[2], b[2], s),
    ]
}

/// The logged commands as a function of time (s from the first row), as the logger made them.
struct Reconstruction<'a> {
    commands: &'a [Actuators],
    sampling: &'a Sampling,
    count: usize,
    logging: CommandLogging,
}

impl Reconstruction<'_> {
    fn at_index(&self, index: i64) -> Actuators {
        self.commands[index.clamp(0, self.commands.len() as i64 - 1) as usize]
    }

    /// The time of row `index` (s from the first row), at the nominal interval beyond the ends.
    fn row_time(&self, index: i64) -> f64 {
        let last = self.commands.len() as i64 - 1;
        let interval = self.sampling.interval();
        match index {
            i if i < 0 => i as f64 * interval,
            i if i > last => self.sampling.offset(last as usize) + (i - last) as f64 * interval,
            i => self.sampling.offset(i as usize),
        }
    }

    /// The mean of the command over `[start, end]` (a sub-interval, shorter than a row interval).
    fn mean(&self, start: f64, end: f64) -> Actuators {
        match self.logging {
            CommandLogging::Sample => self.band_limited(0.5 * (start + end)),
            // Held over [t_j, t_{j+1}); the period mean is the same, one row earlier.
            CommandLogging::Held => self.steps(start, end, 0),
            CommandLogging::PeriodMean => self.steps(start, end, 1),
        }
    }

    /// A command constant over `[t_j, t_{j+1})`, the one of row `j + rows_later`, averaged over
    /// `[start, end]`.
    fn steps(&self, start: f64, end: f64, rows_later: i64) -> Actuators {
        let (first, crosses, weight_first) = match self.sampling {
            // One interval later, in seconds: the arithmetic of a fixed step.
            Sampling::Uniform { interval: dt, .. } => {
                let shift = rows_later as f64 * dt;
                let (start, end) = (start + shift, end + shift);
                let first = (start / dt).floor();
                let boundary = (first + 1.0) * dt;
                let weight_first = (boundary - start) / (end - start);
                (first as i64, end > boundary, weight_first)
            }
            Sampling::Stamped { .. } => {
                let first = self.sampling.position(start).floor() as i64;
                let boundary = self.row_time(first + 1);
                let weight_first = (boundary - start) / (end - start);
                (first + rows_later, end > boundary, weight_first)
            }
        };
        let a = self.at_index(first);
        if !crosses {
            return a;
        }
        let b = self.at_index(first + 1);
        let mut mixed = [0.0; MAX_ACTUATORS];
        for i in 0..self.count {
            mixed[i] = weight_first * a[i] + (1.0 - weight_first) * b[i];
        }
        mixed
    }

    /// The curve through the samples at time `t`: Lanczos interpolation with [`LANCZOS_LOBES`]
    /// lobes, a windowed sinc (within 4 · 10⁻³ of a sinusoid's amplitude at a sixteenth of the log
    /// rate). On stamps the kernel runs in rows, time mapped to rows piecewise linearly, so that the
    /// curve passes through every sample at its time (a kernel on true time distances does not,
    /// and read as delays: docs/mismatch-history.md).
    fn band_limited(&self, t: f64) -> Actuators {
        let position = self.sampling.position(t);
        let j = position.floor();
        let s = position - j;
        let j = j as i64;
        let a = LANCZOS_LOBES as i64;
        let mut out = [0.0; MAX_ACTUATORS];
        let mut total = 0.0;
        for m in (1 - a)..=a {
            let x = s - m as f64;
            let weight = lanczos(x, LANCZOS_LOBES as f64);
            total += weight;
            let p = self.at_index(j + m);
            for i in 0..self.count {
                out[i] += weight * p[i];
            }
        }
        out.map(|v| v / total)
    }
}

/// For each sub-interval of a row interval (the pattern repeats from row to row): the index,
/// relative to the row, of the first sample the Lanczos curve at its midpoint uses (shifted back by
/// `shift` seconds) and the normalised weights of the `2 a` samples.
fn lanczos_phases(dt: f64, shift: f64) -> Vec<(i64, Vec<f64>)> {
    let a = LANCZOS_LOBES as i64;
    (0..SUBSTEPS)
        .map(|r| {
            let position = (r as f64 + 0.5) / SUBSTEPS as f64 - shift / dt;
            let j = position.floor();
            let s = position - j;
            let weights: Vec<f64> = ((1 - a)..=a)
                .map(|m| lanczos(s - m as f64, LANCZOS_LOBES as f64))
                .collect();
            let total: f64 = weights.iter().sum();
            (
                j as i64 + 1 - a,
                weights.into_iter().map(|w| w / total).collect(),
            )
        })
        .collect()
}

/// Lobes of the Lanczos kernel.
const LANCZOS_LOBES: usize = 4;

/// The Lanczos kernel `sinc(x) sinc(x / a)` on `|x| < a`.
fn lanczos(x: f64, a: f64) -> f64 {
    if x.abs() < 1e-12 {
        return 1.0;
    }
    if x.abs() >= a {
        return 0.0;
    }
    let pi_x = std::f64::consts::PI * x;
    a * pi_x.sin() * (pi_x / a).sin() / (pi_x * pi_x)
}

/// The actuator states at the midpoint of every sub-interval: the command the vehicle received
/// (the logged commands as `logger` describes them; instantaneous samples through `samples`' domain
/// and limits), `delay` seconds late, through a first-order lag of time constant `lag` (exact for
/// an input constant over each sub-interval).
pub fn actuator_trace(
    samples: &CommandSamples,
    sampling: &Sampling,
    logger: &Logger,
    delay: f64,
    lag: f64,
) -> Vec<Actuators> {
    let (commands, count) = (&samples.values[..], samples.count);
    let n = commands.len();
    let dt = sampling.interval();
    let mut h = dt / SUBSTEPS as f64;
    let total = (n - 1) * SUBSTEPS;
    let reconstruction = Reconstruction {
        commands,
        sampling,
        count,
        logging: logger.command,
    };
    // Received at t: logged at t − offset; applied at t: received at t − delay. A sampled command
    // held for a control period acts, on average, half a period after its sample.
    let hold = match (logger.command, logger.controller_rate_hz) {
        (CommandLogging::Sample, Some(rate)) => 0.5 / rate,
        _ => 0.0,
    };
    let shift = logger.command_time_offset_s + hold + delay;
    let mut state = samples.commands(reconstruction.mean(-shift, h - shift));
    let decays = |h: f64| {
        if lag > 0.0 {
            ((-h / lag).exp(), (-h / (2.0 * lag)).exp())
        } else {
            (0.0, 0.0)
        }
    };
    let (mut decay_full, mut decay_half) = decays(h);
    // Evenly spaced, the Lanczos weights repeat from row to row.
    let phases = (logger.command == CommandLogging::Sample && sampling.is_uniform())
        .then(|| lanczos_phases(dt, shift));
    let mut out = Vec::with_capacity(total);
    for step in 0..total {
        let (k, j) = (step / SUBSTEPS, step % SUBSTEPS);
        let start = match sampling {
            Sampling::Uniform { .. } => step as f64 * h - shift,
            Sampling::Stamped { .. } => {
                if j == 0 {
                    h = sampling.interval_at(k) / SUBSTEPS as f64;
                    (decay_full, decay_half) = decays(h);
                }
                sampling.offset(k) + j as f64 * h - shift
            }
        };
        let input = match &phases {
            Some(phases) => {
                let (base, weights) = &phases[j];
                let first = k as i64 + base;
                let mut value = [0.0; MAX_ACTUATORS];
                for (m, w) in weights.iter().enumerate() {
                    let p = reconstruction.at_index(first + m as i64);
                    for i in 0..count {
                        value[i] += w * p[i];
                    }
                }
                samples.commands(value)
            }
            None if logger.command == CommandLogging::Sample => {
                samples.commands(reconstruction.band_limited(start + 0.5 * h))
            }
            None => reconstruction.mean(start, start + h),
        };
        if j == 0 && segment_starts_at(sampling, k) {
            state = input;
        }
        if lag > 0.0 {
            let mut midpoint = [0.0; MAX_ACTUATORS];
            for i in 0..count {
                midpoint[i] = input[i] + (state[i] - input[i]) * decay_half;
                state[i] = input[i] + (state[i] - input[i]) * decay_full;
            }
            out.push(midpoint);
        } else {
            out.push(input);
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use physics::actuators;

    fn even(dt: f64, len: usize) -> Sampling {
        Sampling::Uniform {
            start: 0.0,
            interval: dt,
            len,
        }
    }

    fn held() -> Logger {
        Logger {
            command: CommandLogging::Held,
            ..Logger::default()
        }
    }

    #[test]
    fn delay_shifts_the_held_commands_and_lag_approaches_them() {
        let commands: Vec<Actuators> = (0..6).map(|k| actuators(&[k as f64])).collect();
        let dt = 0.02;
        let plain = actuator_trace(
            &CommandSamples::plain(&commands, 1),
            &even(dt, 6),
            &held(),
            0.0,
            0.0,
        );
        assert_eq!(plain[SUBSTEPS * 2 + 3][0], 2.0);
        // Delay of exactly one interval: interval 3 sees command 2.
        let delayed = actuator_trace(
            &CommandSamples::plain(&commands, 1),
            &even(dt, 6),
            &held(),
            dt,
            0.0,
        );
        assert!((delayed[SUBSTEPS * 3 + 5][0] - 2.0).abs() < 1e-12);
        // Half a sub-interval of delay mixes two commands half and half at the switch.
        let half = actuator_trace(
            &CommandSamples::plain(&commands, 1),
            &even(dt, commands.len()),
            &held(),
            dt / SUBSTEPS as f64 / 2.0,
            0.0,
        );
        assert!((half[SUBSTEPS * 2][0] - 1.5).abs() < 1e-9);
        // The period mean of row j held over the interval before it: one interval earlier.
        let mean = Logger {
            command: CommandLogging::PeriodMean,
            ..Logger::default()
        };
        let early = actuator_trace(
            &CommandSamples::plain(&commands, 1),
            &even(dt, 6),
            &mean,
            0.0,
            0.0,
        );
        assert!((early[SUBSTEPS * 2 + 3][0] - 3.0).abs() < 1e-12);
        // A lag follows a step monotonically, without overshoot, and reaches 1 − e^(−t/τ).
        let step: Vec<Actuators> = (0..6)
            .map(|k| actuators(&[if k >= 2 { 1.0 } else { 0.0 }]))
            .collect();
        let lagged = actuator_trace(
            &CommandSamples::plain(&step, 1),
            &even(dt, 6),
            &held(),
            0.0,
            0.05,
        );
        let response: Vec<f64> = lagged[SUBSTEPS * 2..].iter().map(|a| a[0]).collect();
        assert!(response.windows(2).all(|w| w[1] > w[0] && w[1] < 1.0));
        let midpoint = (SUBSTEPS as f64 + 0.5) * dt / SUBSTEPS as f64;
        assert!((response[SUBSTEPS] - (1.0 - (-midpoint / 0.05f64).exp())).abs() < 1e-12);
    }

    /// Samples of a smooth command are reconstructed to 4 parts in 10³ between the samples
    /// (away from the ends, where the kernel runs out of samples), and a sampled command's delay
    /// moves the curve by exactly that time.
    #[test]
    fn sampled_commands_are_interpolated_smoothly() {
        let dt = 0.02;
        let f = |t: f64| (2.0 * std::f64::consts::PI * 3.0 * t).sin();
        let commands: Vec<Actuators> = (0..100).map(|k| actuators(&[f(k as f64 * dt)])).collect();
        let trace = actuator_trace(
            &CommandSamples::plain(&commands, 1),
            &even(dt, commands.len()),
            &Logger::default(),
            0.0,
            0.0,
        );
        let h = dt / SUBSTEPS as f64;
        for (i, value) in trace.iter().enumerate().skip(5 * SUBSTEPS).take(880) {
            let t = (i as f64 + 0.5) * h;
            assert!((value[0] - f(t)).abs() < 4e-3, "{} vs {}", value[0], f(t));
        }
        let delayed = actuator_trace(
            &CommandSamples::plain(&commands, 1),
            &even(dt, commands.len()),
            &Logger::default(),
            0.013,
            0.0,
        );
        for (i, value) in delayed.iter().enumerate().skip(6 * SUBSTEPS).take(880) {
            let t = (i as f64 + 0.5) * h - 0.013;
            assert!((value[0] - f(t)).abs() < 4e-3);
        }
    }

    /// Samples taken at jittered times (±30 % of the interval) are reconstructed through each
    /// sample at its own time, and between them within 0.05 of a 3 Hz sinusoid sampled at 50 Hz
    /// (measured 0.046; 4 · 10⁻³ evenly spaced).
    #[test]
    fn jittered_samples_are_placed_at_their_times() {
        let dt = 0.02;
        let f = |t: f64| (2.0 * std::f64::consts::PI * 3.0 * t).sin();
        let time: Vec<f64> = (0..100)
            .map(|k| k as f64 * dt + 0.3 * dt * (k as f64 * 2.399).sin())
            .collect();
        let commands: Vec<Actuators> = time.iter().map(|&t| actuators(&[f(t)])).collect();
        let sampling = Sampling::new(&time);
        let reconstruction = Reconstruction {
            commands: &commands,
            sampling: &sampling,
            count: 1,
            logging: CommandLogging::Sample,
        };
        for k in 10..90 {
            let at_sample = reconstruction.band_limited(time[k] - time[0])[0];
            assert!((at_sample - commands[k][0]).abs() < 1e-12);
        }
        let trace = actuator_trace(
            &CommandSamples::plain(&commands, 1),
            &sampling,
            &Logger::default(),
            0.0,
            0.0,
        );
        let worst = (10..90)
            .flat_map(|k| (0..SUBSTEPS).map(move |j| (k, j)))
            .map(|(k, j)| {
                let h = (time[k + 1] - time[k]) / SUBSTEPS as f64;
                let t = time[k] + (j as f64 + 0.5) * h;
                (trace[k * SUBSTEPS + j][0] - f(t)).abs()
            })
            .fold(0.0, f64::max);
        assert!(worst < 0.05, "{worst}");
    }

    /// A rotor whose thrust demand dips below zero holds speed 0 on the samples there, and its
    /// speed bends sharply where the demand crosses zero. Reconstructed through its per-rotor
    /// thrust, with the held run continued beyond the limit, the thrust between the samples follows
    /// the clipped demand within 2 · 10⁻³; a curve through the speeds missed it by up to 1.7 · 10⁻².
    #[test]
    fn a_rotor_held_at_zero_is_reconstructed_through_its_thrust() {
        use crate::recording::command_samples::{SampleDomain, detect_limits};
        let dt = 0.02;
        let demand = |t: f64| 0.3 + 0.5 * (2.0 * std::f64::consts::PI * 2.0 * t).sin();
        let speeds: Vec<Actuators> = (0..100)
            .map(|k| actuators(&[demand(k as f64 * dt).max(0.0).sqrt()]))
            .collect();
        let limits = detect_limits(&speeds, 1);
        assert_eq!(limits[0].lower, Some(0.0));
        let error = |samples: &CommandSamples| {
            let trace = actuator_trace(samples, &even(dt, 100), &Logger::default(), 0.0, 0.0);
            let h = dt / SUBSTEPS as f64;
            (10 * SUBSTEPS..90 * SUBSTEPS)
                .map(|i| (trace[i][0].powi(2) - demand((i as f64 + 0.5) * h).max(0.0)).abs())
                .fold(0.0, f64::max)
        };
        let through_thrust = CommandSamples::new(&speeds, 1, SampleDomain::SquaredSpeed, &limits);
        assert!(error(&through_thrust) < 2e-3, "{}", error(&through_thrust));
        let through_speeds = CommandSamples::plain(&speeds, 1);
        assert!(error(&through_speeds) > 1e-2, "{}", error(&through_speeds));
    }
}
