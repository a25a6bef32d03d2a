//! The worked example's family of systems: forced, damped Duffing oscillators whose parameters
//! differ between tasks,
//!
//! x' = v,   v' = −δ·v − α·x − β·x³ + b·u,   u(t) = A·cos(ω₁t + φ₁) + (A/2)·cos(ω₂t + φ₂),
//!
//! each task a draw of (δ, α, β, b, A, ω₁, ω₂, φ₁, φ₂, x₀, v₀) from the configured ranges,
//! integrated with RK4 and sampled with Gaussian measurement noise on x and v (u is known
//! exactly, as a commanded input is). Every draw comes from one ChaCha8 stream per task, seeded by
//! the recorded seed and the task's index.

use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, StandardNormal};
use serde::{Deserialize, Serialize};

/// A closed range `[low, high]` a parameter is drawn from uniformly.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ParameterRange {
    pub low: f64,
    pub high: f64,
}

impl ParameterRange {
    fn draw(&self, rng: &mut ChaCha8Rng) -> f64 {
        if self.high > self.low {
            rng.random_range(self.low..=self.high)
        } else {
            self.low
        }
    }
}

/// The family and its sampling.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FamilyConfig {
    /// δ, the damping.
    pub damping: ParameterRange,
    /// α, the linear stiffness.
    pub stiffness: ParameterRange,
    /// β, the cubic stiffness.
    pub cubic_stiffness: ParameterRange,
    /// b, the input gain (e.g. the inverse of a payload's mass).
    pub input_gain: ParameterRange,
    /// A, the forcing amplitude.
    pub forcing_amplitude: ParameterRange,
    /// ω₁, the first forcing frequency, rad/s.
    pub forcing_frequency: ParameterRange,
    /// ω₂, the second forcing frequency, rad/s.
    pub second_frequency: ParameterRange,
    /// x₀ and v₀ are drawn from this range.
    pub initial_state: ParameterRange,
    /// Standard deviation of the noise added to the sampled x and v.
    pub noise_std: f64,
    /// Sampling interval, seconds.
    pub sample_interval: f64,
    /// RK4 steps per sampling interval.
    pub substeps: usize,
    /// Samples per task.
    pub rows: usize,
}

/// The parameters of one task, as drawn.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct TaskParameters {
    pub damping: f64,
    pub stiffness: f64,
    pub cubic_stiffness: f64,
    pub input_gain: f64,
    pub forcing_amplitude: f64,
    pub forcing_frequency: f64,
    pub second_frequency: f64,
    pub phases: [f64; 2],
    pub initial_state: [f64; 2],
}

impl TaskParameters {
    fn input(&self, t: f64) -> f64 {
        let a = self.forcing_amplitude;
        a * (self.forcing_frequency * t + self.phases[0]).cos()
            + 0.5 * a * (self.second_frequency * t + self.phases[1]).cos()
    }

    fn derivative(&self, [x, v]: [f64; 2], t: f64) -> [f64; 2] {
        let acceleration =
            -self.damping * v - self.stiffness * x - self.cubic_stiffness * x * x * x
                + self.input_gain * self.input(t);
        [v, acceleration]
    }

    /// One RK4 step of length `h` from `state` at time `t`.
    fn step(&self, state: [f64; 2], t: f64, h: f64) -> [f64; 2] {
        let add = |a: [f64; 2], b: [f64; 2], s: f64| [a[0] + s * b[0], a[1] + s * b[1]];
        let k1 = self.derivative(state, t);
        let k2 = self.derivative(add(state, k1, h / 2.0), t + h / 2.0);
        let k3 = self.derivative(add(state, k2, h / 2.0), t + h / 2.0);
        let k4 = self.derivative(add(state, k3, h), t + h);
        [
            state[0] + h / 6.0 * (k1[0] + 2.0 * k2[0] + 2.0 * k3[0] + k4[0]),
            state[1] + h / 6.0 * (k1[1] + 2.0 * k2[1] + 2.0 * k3[1] + k4[1]),
        ]
    }
}

/// One simulated task: columns t, x, v, u and the parameters drawn.
#[derive(Clone, Debug, PartialEq)]
pub struct SimulatedTask {
    pub parameters: TaskParameters,
    pub time: Vec<f64>,
    pub x: Vec<f64>,
    pub v: Vec<f64>,
    pub u: Vec<f64>,
}

impl SimulatedTask {
    /// The task as CSV text with the header `t,x,v,u` (shortest round-trip numbers).
    pub fn csv(&self) -> String {
        let mut text = String::from("t,x,v,u\n");
        for k in 0..self.time.len() {
            text.push_str(&format!(
                "{},{},{},{}\n",
                self.time[k], self.x[k], self.v[k], self.u[k]
            ));
        }
        text
    }
}

/// A standard normal draw.
fn normal(rng: &mut ChaCha8Rng) -> f64 {
    StandardNormal.sample(rng)
}

/// Task `index` of the family drawn with `seed`.
pub fn simulate_task(family: &FamilyConfig, seed: u64, index: u64) -> SimulatedTask {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    rng.set_stream(index);
    let mut phase = || rng.random_range(0.0..std::f64::consts::TAU);
    let phases = [phase(), phase()];
    let parameters = TaskParameters {
        damping: family.damping.draw(&mut rng),
        stiffness: family.stiffness.draw(&mut rng),
        cubic_stiffness: family.cubic_stiffness.draw(&mut rng),
        input_gain: family.input_gain.draw(&mut rng),
        forcing_amplitude: family.forcing_amplitude.draw(&mut rng),
        forcing_frequency: family.forcing_frequency.draw(&mut rng),
        second_frequency: family.second_frequency.draw(&mut rng),
        phases,
        initial_state: [
            family.initial_state.draw(&mut rng),
            family.initial_state.draw(&mut rng),
        ],
    };
    let h = family.sample_interval / family.substeps.max(1) as f64;
    let mut state = parameters.initial_state;
    let mut task = SimulatedTask {
        parameters,
        time: Vec::with_capacity(family.rows),
        x: Vec::with_capacity(family.rows),
        v: Vec::with_capacity(family.rows),
        u: Vec::with_capacity(family.rows),
    };
    for k in 0..family.rows {
        let t = k as f64 * family.sample_interval;
        task.time.push(t);
        task.x.push(state[0] + family.noise_std * normal(&mut rng));
        task.v.push(state[1] + family.noise_std * normal(&mut rng));
        task.u.push(parameters.input(t));
        for s in 0..family.substeps.max(1) {
            state = parameters.step(state, t + s as f64 * h, h);
        }
    }
    task
}

#[cfg(test)]
mod tests {
    use super::*;

    fn family() -> FamilyConfig {
        let range = |low, high| ParameterRange { low, high };
        FamilyConfig {
            damping: range(0.1, 0.5),
            stiffness: range(0.5, 2.0),
            cubic_stiffness: range(0.2, 2.0),
            input_gain: range(0.6, 1.4),
            forcing_amplitude: range(0.5, 1.5),
            forcing_frequency: range(0.6, 1.4),
            second_frequency: range(1.5, 3.0),
            initial_state: range(-1.0, 1.0),
            noise_std: 0.0,
            sample_interval: 0.01,
            substeps: 4,
            rows: 400,
        }
    }

    #[test]
    fn the_samples_follow_the_equations_and_the_draws_are_seeded() {
        let task = simulate_task(&family(), 7, 3);
        assert_eq!(task, simulate_task(&family(), 7, 3));
        assert_ne!(task.parameters, simulate_task(&family(), 7, 4).parameters);
        let p = task.parameters;
        let dt = 0.01;
        // Central differences of the noise-free samples against the equations.
        for k in 1..task.time.len() - 1 {
            let v_dot = (task.v[k + 1] - task.v[k - 1]) / (2.0 * dt);
            let x = task.x[k];
            let expected = -p.damping * task.v[k] - p.stiffness * x - p.cubic_stiffness * x * x * x
                + p.input_gain * task.u[k];
            assert!(
                (v_dot - expected).abs() < 1e-3,
                "row {k}: {v_dot} vs {expected}"
            );
        }
        assert!(task.csv().starts_with("t,x,v,u\n0,"));
    }
}
