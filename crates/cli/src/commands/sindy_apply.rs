//! `learn sindy predict|simulate --model M --csv NEW`: a model saved by `learn sindy --out`
//! (`sindy-model/1`) applied to a new recording, as PySINDy's `predict` and `simulate`.

use std::path::PathBuf;

use anyhow::Context;
use sindy::{Derivative, Mat, SindyModel};

use output_set::{Existing, OutputSet};

use super::Global;
use super::sindy::{Recording, r2_text, read_recording};

#[derive(clap::Subcommand, Debug)]
pub enum ApplyCommand {
    /// Predict ẋ on a new recording with a saved model, scored against the derivatives the
    /// model's estimator takes from the recording; --out writes the prediction as CSV.
    Predict(ApplyArgs),
    /// Integrate a saved model from the first row of a new recording, driven by its controls
    /// (RK4 over its time stamps), against the recorded states; --out writes the simulation.
    Simulate(ApplyArgs),
}

#[derive(clap::Args, Debug)]
pub struct ApplyArgs {
    /// A model written by `learn sindy --out`.
    #[arg(long)]
    pub model: PathBuf,
    /// A numeric CSV with the model's state and control columns and a time column.
    #[arg(long)]
    pub csv: PathBuf,
    /// The time column (strictly increasing).
    #[arg(long, default_value = "t")]
    pub time: String,
    /// Write the result as CSV here: the time column, then ẋ (predict, columns `x'`) or the
    /// simulated states (simulate). Never overwrites an existing file without --force.
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Allow --out to replace an existing file.
    #[arg(long)]
    pub force: bool,
}

pub fn run(_global: &Global, command: ApplyCommand) -> anyhow::Result<()> {
    let (args, simulate) = match command {
        ApplyCommand::Predict(args) => (args, false),
        ApplyCommand::Simulate(args) => (args, true),
    };
    let text = super::read_policy_json(&args.model)?;
    let model = SindyModel::from_json(&text, &args.model)?;
    let output = match &args.out {
        Some(out) => {
            let mut set = OutputSet::new(if simulate {
                "sindy simulate"
            } else {
                "sindy predict"
            });
            set.input("the --model input", &args.model);
            set.input("the --csv input", &args.csv);
            let file = set.file(out, "--out", Existing::from_force(args.force));
            Some((set.prepare()?, file))
        }
        None => None,
    };
    let columns: Vec<&str> = model
        .state_names()
        .iter()
        .chain(model.control_names())
        .map(String::as_str)
        .collect();
    // A simulation needs no derivative: the least demanding estimator checks the time axis.
    let derivative = if simulate {
        Derivative::Forward
    } else {
        model.derivative()
    };
    let recording = read_recording(
        &args.csv,
        &args.time,
        model.state_names().len(),
        &columns,
        derivative,
    )?;
    let (names, values) = if simulate {
        simulated(&model, &recording)?
    } else {
        predicted(&model, &recording)?
    };
    if let Some((staged, file)) = output {
        let mut header = vec![args.time.clone()];
        header.extend(names);
        let mut table = vec![recording.trajectory.time.clone()];
        table.extend((0..values.ncols()).map(|j| values.col(j).iter().copied().collect()));
        super::staged_write(&staged, || {
            data::write_numeric_csv(staged.path(file), &header, &table)
        })?;
        staged.commit()?;
    }
    if let Some(out) = &args.out {
        note!("written to {}", out.display());
    }
    Ok(())
}

/// ẋ predicted on every row, its score printed; the columns' names `x'`.
fn predicted(model: &SindyModel, recording: &Recording) -> anyhow::Result<(Vec<String>, Mat<f64>)> {
    let trajectory = &recording.trajectory;
    let prediction = model.predict(trajectory.states.as_ref(), trajectory.controls.as_ref())?;
    let score = model
        .score(trajectory)
        .with_context(|| format!("scoring on {}", recording.path.display()))?;
    say!(
        "{}: {} samples; MSE of ẋ {:.6}, {}",
        recording.path.display(),
        trajectory.time.len(),
        score.mse,
        r2_text(model, &score)
    );
    let names = model
        .state_names()
        .iter()
        .map(|s| format!("{s}'"))
        .collect();
    Ok((names, prediction))
}

/// The states simulated from the first row, with each state's root-mean-square error against the
/// recording printed.
fn simulated(model: &SindyModel, recording: &Recording) -> anyhow::Result<(Vec<String>, Mat<f64>)> {
    let trajectory = &recording.trajectory;
    let first: Vec<f64> = trajectory.states.row(0).iter().copied().collect();
    let states = model
        .simulate(&first, &trajectory.time, trajectory.controls.as_ref())
        .with_context(|| format!("simulating over {}", recording.path.display()))?;
    let rows = states.nrows() as f64;
    let errors: Vec<String> = model
        .state_names()
        .iter()
        .enumerate()
        .map(|(j, name)| {
            let squares: f64 = (0..states.nrows())
                .map(|i| (states[(i, j)] - trajectory.states[(i, j)]).powi(2))
                .sum();
            format!("{name} {:.6}", (squares / rows).sqrt())
        })
        .collect();
    say!(
        "{}: {} samples simulated from the first; RMSE against the recording: {}",
        recording.path.display(),
        states.nrows(),
        errors.join(", ")
    );
    Ok((model.state_names().to_vec(), states))
}
