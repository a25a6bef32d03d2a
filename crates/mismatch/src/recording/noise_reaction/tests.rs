use std::path::PathBuf;

use data::RateFrame;
use physics::MAX_ACTUATORS;
use physics::vector::{mat_mul, rotation_from_rotation_vector};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;

use super::*;
use crate::recording::command_samples::CommandSamples;

const DT: f64 = 0.02;
const ROWS: usize = 2000;

type Commands = Vec<Actuators>;

use crate::improve::simex::gaussian;

fn noise(rng: &mut ChaCha8Rng, sigma: f64) -> Vec3 {
    std::array::from_fn(|_| gaussian(rng, sigma))
}

/// A flight whose smooth motion is consistent (rates and velocities are the derivatives of the
/// attitude and position), logged with white noise; the commands react to every logged noise, as a
/// controller's sampled command does. Returns the recording, per row the reaction to the attitude
/// and position noise and the reaction to the velocity noise, and the true velocity changes.
fn flight(seed: u64) -> (Recording, Commands, Commands, Vec<Vec3>) {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let axis = {
        let u: Vec3 = [0.3, 0.8, 0.5];
        let n = (u[0] * u[0] + u[1] * u[1] + u[2] * u[2]).sqrt();
        u.map(|v| v / n)
    };
    let mixing = [
        [-1.0, 1.0, 1.0],
        [1.0, -1.0, 1.0],
        [1.0, 1.0, -1.0],
        [-1.0, -1.0, -1.0],
    ];
    let mut recording = Recording {
        path: PathBuf::from("synthetic.csv"),
        time: Vec::new(),
        sampling: sindy::sampling::Sampling::Uniform {
            start: 0.0,
            interval: DT,
            len: ROWS,
        },
        rotation: Vec::new(),
        velocity: Vec::new(),
        position: Vec::new(),
        position_logged: true,
        body_rate: Vec::new(),
        rate_frame: RateFrame::Body,
        rate_frame_errors: (0.0, 0.0),
        commands: Vec::new(),
        command_spread: [0.0; MAX_ACTUATORS],
        command_rate_hz: None,
        command_limits: Default::default(),
        samples: CommandSamples::plain(&[], 4),
        noise_reaction: None,
    };
    let mut attitude_position_reaction = Vec::new();
    let mut velocity_reaction = Vec::new();
    let mut true_velocity = Vec::new();
    for k in 0..ROWS {
        let t = k as f64 * DT;
        let angle = 0.3 * (1.3 * t).sin() + 0.1 * (0.4 * t).sin();
        let angle_rate = 0.39 * (1.3 * t).cos() + 0.04 * (0.4 * t).cos();
        let position = [(0.5 * t).sin(), (0.3 * t).cos(), 0.2 * (0.7 * t).sin()];
        let velocity = [
            0.5 * (0.5 * t).cos(),
            -0.3 * (0.3 * t).sin(),
            0.14 * (0.7 * t).cos(),
        ];
        let (rate_noise, attitude_noise) = (noise(&mut rng, 0.008), noise(&mut rng, 0.002));
        let (velocity_noise, position_noise) = (noise(&mut rng, 0.005), noise(&mut rng, 0.002));
        let truth = rotation_from_rotation_vector(axis.map(|u| u * angle));
        recording.time.push(t);
        recording.rotation.push(mat_mul(
            &truth,
            &rotation_from_rotation_vector(attitude_noise),
        ));
        recording.body_rate.push(std::array::from_fn(|a| {
            axis[a] * angle_rate + rate_noise[a]
        }));
        recording
            .velocity
            .push(std::array::from_fn(|a| velocity[a] + velocity_noise[a]));
        recording
            .position
            .push(std::array::from_fn(|a| position[a] + position_noise[a]));
        true_velocity.push(velocity);
        let mut command = [0.0; MAX_ACTUATORS];
        let mut reaction = [0.0; MAX_ACTUATORS];
        let mut to_velocity = [0.0; MAX_ACTUATORS];
        for i in 0..4 {
            let react = |gain: f64, n: Vec3| -> f64 {
                (0..3).map(|a| 0.01 * mixing[i][a] * gain * n[a]).sum()
            };
            reaction[i] = react(-100.0, attitude_noise) + react(-55.0, position_noise);
            to_velocity[i] = react(40.0, velocity_noise);
            command[i] = 0.6
                + 0.05 * (2.0 * t + i as f64).sin()
                + reaction[i]
                + react(-18.0, rate_noise)
                + to_velocity[i];
        }
        recording.commands.push(command);
        attitude_position_reaction.push(reaction);
        velocity_reaction.push(to_velocity);
    }
    recording.samples = CommandSamples::plain(&recording.commands, 4);
    let changes = true_velocity
        .windows(2)
        .map(|w| std::array::from_fn(|a| w[1][a] - w[0][a]))
        .collect();
    (
        recording,
        attitude_position_reaction,
        velocity_reaction,
        changes,
    )
}

/// The RMS of `corrected − (logged − 0.9 reaction)` over the RMS of `0.9 reaction`: 1 when nothing
/// was removed, 0 when exactly the unfelt share was.
fn removal_error(logged: &[Actuators], corrected: &[Actuators], reaction: &[Actuators]) -> f64 {
    let (mut excess, mut error) = (0.0, 0.0);
    for k in 0..logged.len() {
        for i in 0..4 {
            let felt = logged[k][i] - 0.9 * reaction[k][i];
            excess += (logged[k][i] - felt).powi(2);
            error += (corrected[k][i] - felt).powi(2);
        }
    }
    (error / excess).sqrt()
}

fn sampling_logger(controller_rate_hz: f64) -> Logger {
    Logger {
        command: CommandLogging::Sample,
        controller_rate_hz: Some(controller_rate_hz),
        ..Logger::default()
    }
}

/// With a controller ten times the log rate, nine tenths of the reaction to the logged attitude and
/// position noise is removed: the commands come out as the vehicle felt them, to a fifth of what
/// the log held in excess.
#[test]
fn the_unfelt_reaction_to_attitude_and_position_noise_is_removed() {
    for seed in [3, 4] {
        let (mut recording, reaction, _, _) = flight(seed);
        let logged = recording.commands.clone();
        assert!(remove(&mut recording, &sampling_logger(500.0), 4));
        let removed = recording.noise_reaction.as_ref().expect("recorded");
        assert!((removed.steps_per_row - 10.0).abs() < 1e-9);
        let ratio = removal_error(&logged, &recording.commands, &reaction);
        assert!(ratio < 0.2, "seed {seed}: error / excess {ratio:.3}");
    }
}

/// A gap in the log (here 0.4 s between rows 999 and 1000, the states going on as if it were one
/// row): the turn and the step across it are not the trapezoid of the rates and velocities, and the
/// increment says nothing of the noise. The removal is as good as without the gap, for the
/// attitude and position noise and, with a predicted change that misses the gap's, the velocity's.
#[test]
fn no_noise_is_read_across_a_gap() {
    for seed in [3, 6] {
        let (mut recording, reaction, to_velocity, mut changes) = flight(seed);
        for t in &mut recording.time[1000..] {
            *t += 0.4;
        }
        recording.sampling = sindy::sampling::Sampling::new(&recording.time);
        assert_eq!(recording.sampling.gaps(), vec![999]);
        let logged = recording.commands.clone();
        assert!(remove(&mut recording, &sampling_logger(500.0), 4));
        let ratio = removal_error(&logged, &recording.commands, &reaction);
        assert!(ratio < 0.2, "seed {seed}: attitude, position {ratio:.3}");
        changes[999] = [0.3, -0.2, 0.1];
        let before = recording.commands.clone();
        assert!(remove_velocity(&mut recording, &changes, [1e-5; 3]));
        let ratio = removal_error(&before, &recording.commands, &to_velocity);
        assert!(ratio < 0.2, "seed {seed}: velocity {ratio:.3}");
    }
}

/// Given the velocity changes a model predicts, the unfelt reaction to the velocity noise goes too
/// (once: a second call changes nothing).
#[test]
fn with_a_predicted_velocity_the_reaction_to_its_noise_is_removed() {
    for seed in [6, 7] {
        let (mut recording, _, reaction, changes) = flight(seed);
        assert!(remove(&mut recording, &sampling_logger(500.0), 4));
        let before = recording.commands.clone();
        assert!(remove_velocity(&mut recording, &changes, [1e-5; 3]));
        let ratio = removal_error(&before, &recording.commands, &reaction);
        assert!(ratio < 0.2, "seed {seed}: error / excess {ratio:.3}");
        let after = recording.commands.clone();
        assert!(!remove_velocity(&mut recording, &changes, [1e-5; 3]));
        assert_eq!(recording.commands, after);
    }
}

/// Nothing is removed when the vehicle felt what the log holds (held commands, a controller at the
/// log rate, period means) or when the logged command did not see the row's measurement.
#[test]
fn only_samples_of_a_faster_controller_taken_with_the_state_are_corrected() {
    assert_eq!(steps_per_row(&sampling_logger(500.0), DT), Some(10.0));
    assert_eq!(steps_per_row(&sampling_logger(50.0), DT), None);
    assert_eq!(steps_per_row(&Logger::default(), DT), None);
    let held = Logger {
        command: CommandLogging::Held,
        ..sampling_logger(500.0)
    };
    let mean = Logger {
        command: CommandLogging::PeriodMean,
        ..sampling_logger(500.0)
    };
    let late = Logger {
        command_time_offset_s: 0.002,
        ..sampling_logger(500.0)
    };
    for logger in [held, mean, late] {
        assert_eq!(steps_per_row(&logger, DT), None, "{logger:?}");
        let (mut recording, ..) = flight(5);
        let logged = recording.commands.clone();
        assert!(!remove(&mut recording, &logger, 4));
        assert_eq!(recording.commands, logged);
        assert!(recording.noise_reaction.is_none());
    }
}

/// The smoother finds white noise from its increments measured with small errors.
#[test]
fn the_smoother_recovers_white_noise_from_its_increments() {
    let mut rng = ChaCha8Rng::seed_from_u64(11);
    let truth: Vec<f64> = (0..1000).map(|_| gaussian(&mut rng, 0.002)).collect();
    let increments: Vec<f64> = truth
        .windows(2)
        .map(|w| w[1] - w[0] + gaussian(&mut rng, 1e-4))
        .collect();
    let lengths = vec![1.0; increments.len()];
    let found = smooth_noise(&increments, 0.002, 1e-4, &lengths);
    let error: f64 = truth.iter().zip(&found).map(|(a, b)| (a - b).powi(2)).sum();
    let total: f64 = truth.iter().map(|a| a * a).sum();
    // The level is fixed only over about σ/step rows: an error of about a fifth is the limit.
    assert!((error / total).sqrt() < 0.25, "{}", (error / total).sqrt());
    assert_eq!(
        smooth_noise(&increments, 0.0, 1e-4, &lengths),
        vec![0.0; 1000]
    );
}

/// The smoother's error, drawn from its posterior, has the variance and the correlation between
/// neighbouring rows of the actual error of [`smooth_noise`] on white noise measured through its
/// increments (A's attitude: σ = 0.002 rad, increments to 1.6·10⁻⁴ rad).
#[test]
fn the_smoothing_error_draw_matches_the_smoothers_error() {
    let (rows, sigma, step) = (20_000, 0.002, 1.6e-4);
    let mut rng = ChaCha8Rng::seed_from_u64(5);
    let truth: Vec<f64> = (0..rows).map(|_| gaussian(&mut rng, sigma)).collect();
    let increments: Vec<f64> = truth
        .windows(2)
        .map(|w| w[1] - w[0] + gaussian(&mut rng, step))
        .collect();
    let lengths = vec![1.0; rows - 1];
    let estimate = smooth_noise(&increments, sigma, step, &lengths);
    let error: Vec<f64> = estimate.iter().zip(&truth).map(|(e, t)| e - t).collect();
    let draw = smoothing_error_draw(sigma, step, &lengths, &mut || gaussian(&mut rng, 1.0));
    let moments = |x: &[f64]| {
        let variance = x.iter().map(|v| v * v).sum::<f64>() / x.len() as f64;
        let lag: f64 = x.windows(2).map(|w| w[0] * w[1]).sum::<f64>() / (x.len() - 1) as f64;
        (variance, lag / variance)
    };
    let ((actual, actual_lag), (drawn, drawn_lag)) = (moments(&error), moments(&draw));
    // Stationary posterior variance of the interior rows: 1 / √(p (p + 4 l)).
    let (p, l) = (sigma.powi(-2), step.powi(-2));
    let theory = 1.0 / (p * (p + 4.0 * l)).sqrt();
    for value in [actual, drawn] {
        assert!(
            (value / theory - 1.0).abs() < 0.1,
            "{actual} {drawn} {theory}"
        );
    }
    assert!(
        (actual_lag - drawn_lag).abs() < 0.03,
        "{actual_lag} {drawn_lag}"
    );
    assert!(actual_lag > 0.8, "the error is smooth: {actual_lag}");
}
