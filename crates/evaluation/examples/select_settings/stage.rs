//! The comparisons `select_settings` can run, and the candidates each one scores.

use learn::{AdaptationConfig, LearnConfig};

/// One comparison of settings.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Stage {
    /// The first comparison: meta-iterations, task batch and inner step, adaptation step and passes.
    Grid,
    /// How far more meta-iterations help.
    Iterations,
    /// Whether averaging the last meta-iterates (Polyak–Ruppert) helps.
    Averaging,
    /// Whether averaged SGD in the online adaptation helps.
    AdaptationAveraging,
    /// The weight λ and bound L of the adaptation's Lipschitz regulariser.
    Lipschitz,
    /// Support and query batches of 128 points per task instead of 64.
    Batch,
    /// More adaptation passes (8, 16, 24) at the configured and at half the step.
    Passes,
    /// The outer (Adam) step β at half and twice the configured value.
    Outer,
    /// The meta-regulariser μ from 0 to 1e-3.
    Regularisation,
    /// Adaptation updates on windows of 2 or 4 consecutive samples (1: the paper).
    Window,
    /// P = 1 or 3 learned basis functions per input instead of the paper's 2.
    Basis,
    /// Inputs clamped to the range they span in the meta-training flights.
    Clamp,
    /// One meta-training task per wind condition (the paper's task) instead of per flight.
    Tasks,
    /// Several initialisations (seeds) per model, keeping the one with the lowest support-tail
    /// MSE, or averaging their predictions (an ensemble), against a single seed.
    Restarts,
}

impl Stage {
    const ALL: [(&'static str, Stage); 14] = [
        ("grid", Stage::Grid),
        ("iterations", Stage::Iterations),
        ("averaging", Stage::Averaging),
        ("adaptation-averaging", Stage::AdaptationAveraging),
        ("lipschitz", Stage::Lipschitz),
        ("batch", Stage::Batch),
        ("passes", Stage::Passes),
        ("outer", Stage::Outer),
        ("regularisation", Stage::Regularisation),
        ("window", Stage::Window),
        ("basis", Stage::Basis),
        ("clamp", Stage::Clamp),
        ("tasks", Stage::Tasks),
        ("restarts", Stage::Restarts),
    ];

    /// The stage named on the command line; the error lists the names.
    pub fn parse(name: &str) -> Result<Self, String> {
        Self::ALL
            .iter()
            .find(|(n, _)| *n == name)
            .map(|(_, stage)| *stage)
            .ok_or_else(|| {
                let names: Vec<&str> = Self::ALL.iter().map(|(n, _)| *n).collect();
                format!(
                    "unknown stage {name:?}: expected one of {}",
                    names.join(", ")
                )
            })
    }
}

/// The meta-training candidates of a stage, named (all within the reproduce budget:
/// iterations × tasks ≤ 3200).
pub fn meta_training_candidates(stage: Stage, base: &LearnConfig) -> Vec<(String, LearnConfig)> {
    // (iterations, tasks, α, iterates averaged)
    let grid: &[(usize, usize, f64, usize)] = match stage {
        Stage::Iterations => &[(800, 4, 0.1, 0), (1600, 4, 0.1, 0)],
        Stage::Averaging => &[(800, 4, 0.1, 0), (800, 4, 0.1, 200), (800, 4, 0.1, 400)],
        Stage::Grid | Stage::Restarts => &[
            (200, 4, 0.1, 0),
            (800, 4, 0.1, 0),
            (400, 8, 0.1, 0),
            (800, 4, 0.05, 0),
        ],
        _ => &[(800, 4, 0.1, 0)],
    };
    let mut candidates: Vec<(String, LearnConfig)> = grid
        .iter()
        .map(|&(iterations, task_batch, inner_step, average_last)| {
            let mut config = base.clone();
            config.meta_training.iterations = iterations;
            config.meta_training.task_batch = task_batch;
            config.meta_training.inner_step = inner_step;
            config.meta_training.average_last = average_last;
            let averaged = if average_last > 0 {
                format!("_average{average_last}")
            } else {
                String::new()
            };
            let name = format!("it{iterations}_tasks{task_batch}_alpha{inner_step}{averaged}");
            (name, config)
        })
        .collect();
    let first = candidates[0].1.clone();
    candidates.extend(stage_variants(stage, &first));
    candidates
}

/// The candidates a stage adds to its first grid point.
fn stage_variants(stage: Stage, first: &LearnConfig) -> Vec<(String, LearnConfig)> {
    let with = |change: &dyn Fn(&mut LearnConfig)| {
        let mut config = first.clone();
        change(&mut config);
        config
    };
    match stage {
        Stage::Batch => vec![(
            "it800_tasks4_alpha0.1_batch128".to_string(),
            with(&|c| {
                c.meta_training.support_batch = 128;
                c.meta_training.query_batch = 128;
            }),
        )],
        Stage::Outer => [0.5, 2.0]
            .into_iter()
            .map(|factor| {
                let config = with(&|c| c.meta_training.outer_step *= factor);
                let name = format!(
                    "it800_tasks4_alpha0.1_beta{}",
                    config.meta_training.outer_step
                );
                (name, config)
            })
            .collect(),
        Stage::Basis => [1, 3]
            .into_iter()
            .map(|p| {
                let config = with(&|c| c.basis_per_input = p);
                (format!("it800_tasks4_alpha0.1_P{p}"), config)
            })
            .collect(),
        Stage::Clamp => vec![(
            "it800_tasks4_alpha0.1_clamped".to_string(),
            with(&|c| c.clamp_inputs = true),
        )],
        // One task per wind condition. A nested-validation meta-training set holds three
        // conditions (a fold's holds four), so a batch draws at most three: three tasks of 64
        // points, and two tasks of 128 points (the same points per meta-iteration as now).
        Stage::Tasks => [(3, 64), (2, 128)]
            .into_iter()
            .map(|(task_batch, points)| {
                let config = with(&|c| {
                    c.meta_training.tasks = learn::TaskGrouping::Condition;
                    c.meta_training.task_batch = task_batch;
                    c.meta_training.support_batch = points;
                    c.meta_training.query_batch = points;
                });
                let name = format!("it800_conditions{task_batch}_batch{points}_alpha0.1");
                (name, config)
            })
            .collect(),
        Stage::Regularisation => [0.0, 1e-4, 1e-3]
            .into_iter()
            .map(|mu| {
                let config = with(&|c| c.meta_training.meta_regularisation = mu);
                (format!("it800_tasks4_alpha0.1_mu{mu}"), config)
            })
            .collect(),
        _ => Vec::new(),
    }
}

/// The adaptation settings a stage scores every meta-trained model with, named.
pub fn adaptation_candidates(stage: Stage, base: &LearnConfig) -> Vec<(String, AdaptationConfig)> {
    let configured = &base.adaptation;
    match stage {
        // (window, step) at the configured passes: the same step, and the step scaled with the
        // window (the same distance per pass as one-sample updates).
        Stage::Window => [(1, 0.0005), (2, 0.0005), (2, 0.001), (4, 0.001), (4, 0.002)]
            .into_iter()
            .map(|(window, step)| {
                let name = format!("window{window}_step{step}_passes{}", configured.passes);
                let config = AdaptationConfig {
                    window,
                    step,
                    ..configured.clone()
                };
                (name, config)
            })
            .collect(),
        // λ = 0 (no regulariser), then λ × L; the other adaptation settings as configured.
        Stage::Lipschitz => [
            (0.0, 1.0),
            (0.01, 1.0),
            (0.01, 0.1),
            (0.1, 1.0),
            (0.1, 0.1),
            (1.0, 1.0),
            (1.0, 0.1),
        ]
        .into_iter()
        .map(|(lipschitz_weight, lipschitz_bound)| {
            let name = format!("lambda{lipschitz_weight}_bound{lipschitz_bound}");
            let config = AdaptationConfig {
                lipschitz_weight,
                lipschitz_bound,
                ..configured.clone()
            };
            (name, config)
        })
        .collect(),
        _ => step_and_pass_candidates(stage, configured),
    }
}

/// Steps (with or without averaged SGD over the last pass) × passes.
fn step_and_pass_candidates(
    stage: Stage,
    configured: &AdaptationConfig,
) -> Vec<(String, AdaptationConfig)> {
    let passes_grid: &[usize] = match stage {
        Stage::Grid => &[4, 8],
        Stage::Passes => &[8, 16, 24],
        Stage::Basis | Stage::Clamp | Stage::Tasks => &[16],
        _ => &[8],
    };
    let steps: &[(f64, bool)] = match stage {
        Stage::Averaging | Stage::Basis | Stage::Clamp | Stage::Tasks => &[(0.0005, false)],
        Stage::AdaptationAveraging => &[(0.0005, false), (0.0005, true), (0.001, true)],
        Stage::Passes | Stage::Outer | Stage::Regularisation => {
            &[(0.0005, false), (0.00025, false)]
        }
        _ => &[(0.0005, false), (0.001, false)],
    };
    let mut adaptations = Vec::new();
    for &(step, average_last_pass) in steps {
        for &passes in passes_grid {
            let averaged = if average_last_pass { "_averaged" } else { "" };
            let config = AdaptationConfig {
                step,
                passes,
                average_last_pass,
                ..configured.clone()
            };
            adaptations.push((format!("step{step}_passes{passes}{averaged}"), config));
        }
    }
    adaptations
}
