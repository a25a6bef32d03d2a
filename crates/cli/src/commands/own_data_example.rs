//! `learn own-data-example --config experiments/own-data/example.json --work DIR --out DIR`: the
//! worked example of LeARN on your own data. Simulates the family's training and test tasks as CSV
//! files in `--work` (which the three user commands can then be tried on), meta-trains on the
//! training files as `learn meta-train --tasks` does, and writes the learning curve
//! (`learning-curve.{svg,md,json}`) to `--out`.

use std::path::{Path, PathBuf};
use std::time::Duration;

use evaluation::own_data::SimulatedTask;
use evaluation::own_data::example::{
    CurveMethod, CurvePoint, ExampleConfig, LearningCurve, run_example,
};
use indicatif::{ProgressBar, ProgressStyle};
use output_set::{Existing, OutputSet};
use report::{CurveFigure, CurveSeries, curve_markdown};

use super::Global;

#[derive(clap::Args, Debug)]
pub struct Args {
    /// The example's configuration.
    #[arg(long, default_value = "experiments/own-data/example.json")]
    pub config: PathBuf,
    /// Where the simulated task files are written (`train/task-NNN.csv`, `test/task-NNN.csv`).
    #[arg(long, default_value = "target/own-data-example")]
    pub work: PathBuf,
    /// Where the learning curve is written.
    #[arg(long, default_value = "results/own-data")]
    pub out: PathBuf,
    /// Replace the files of an earlier run in --work and --out.
    #[arg(long)]
    pub force: bool,
}

/// The files written to `--out`.
const CURVE_FILES: [&str; 3] = [
    "learning-curve.svg",
    "learning-curve.md",
    "learning-curve.json",
];

fn task_file(kind: &str, index: usize) -> PathBuf {
    Path::new(kind).join(format!("task-{index:03}.csv"))
}

pub fn run(global: &Global, args: Args) -> anyhow::Result<()> {
    let config = ExampleConfig::load(&args.config)?;
    let mut set = OutputSet::new("own-data-example");
    set.input("the --config input", &args.config);
    if let Some(learn_config) = &config.learn_config {
        set.input("the learn_config input", learn_config);
    }
    let existing = Existing::from_force(args.force);
    let work = set.folder(&args.work, "--work", existing);
    let out = set.folder(&args.out, "--out", existing);
    let mut train_files = Vec::new();
    for index in 0..config.training_tasks {
        train_files.push(set.file_in(work, task_file("train", index)));
    }
    let mut test_files = Vec::new();
    for index in 0..config.test_tasks {
        test_files.push(set.file_in(work, task_file("test", index)));
    }
    for name in CURVE_FILES {
        set.file_in(out, name);
    }
    let staged = set.prepare()?;
    let (train, test) = config.simulate();
    let staging = staged.dir(work).to_path_buf();
    write_tasks(&staged, &staging, &[("train", &train), ("test", &test)])?;
    let staged_test: Vec<(PathBuf, _)> = test
        .iter()
        .enumerate()
        .map(|(index, task)| (staging.join(task_file("test", index)), task.parameters))
        .collect();
    let pattern = format!("{}/train/task-*.csv", staging.display());
    let bar = progress(global.show_progress(), config.training_tasks);
    let curve = run_example(&config, &pattern, &staged_test, &|done| {
        bar.set_position(done as u64)
    });
    bar.finish_and_clear();
    let mut curve =
        curve.map_err(|error| anyhow::anyhow!(staged.in_final_terms(&error.to_string())))?;
    for (task, final_path) in curve.test_tasks.iter_mut().zip(&test_files) {
        task.file = final_path.clone();
    }
    let (figure, table) = render(&curve, &evaluation::git_commit(Path::new(".")))?;
    let out_dir = staged.dir(out).to_path_buf();
    super::staged_write(&staged, || {
        std::fs::write(out_dir.join(CURVE_FILES[0]), &figure)?;
        std::fs::write(out_dir.join(CURVE_FILES[1]), &table)?;
        std::fs::write(
            out_dir.join(CURVE_FILES[2]),
            serde_json::to_string_pretty(&curve)? + "\n",
        )
    })?;
    staged.commit()?;
    say!("{table}");
    note!(
        "meta-training: {:.1} s; wrote {} task files under {} and {} under {}",
        curve.meta_training_seconds,
        train_files.len() + test_files.len(),
        args.work.display(),
        CURVE_FILES.join(", "),
        args.out.display()
    );
    Ok(())
}

/// Each kind's tasks as `kind/task-NNN.csv` under the staging folder `staging`.
fn write_tasks(
    staged: &output_set::Staged,
    staging: &Path,
    kinds: &[(&str, &Vec<SimulatedTask>)],
) -> anyhow::Result<()> {
    for (kind, tasks) in kinds {
        let folder = staging.join(kind);
        super::staged_write(staged, || std::fs::create_dir_all(&folder))?;
        for (index, task) in tasks.iter().enumerate() {
            let path = staging.join(task_file(kind, index));
            super::staged_write(staged, || std::fs::write(&path, task.csv()))?;
        }
    }
    Ok(())
}

/// A bar over the meta-iterations; its length is set from the settings once known.
fn progress(show: bool, _tasks: usize) -> ProgressBar {
    if !show {
        return ProgressBar::hidden();
    }
    let bar = ProgressBar::new(0).with_message("meta-train");
    bar.set_style(
        ProgressStyle::with_template("{msg:>12} {pos} iterations, {elapsed}")
            .expect("valid template"),
    );
    bar.enable_steady_tick(Duration::from_millis(250));
    bar
}

/// One series per method of `statistic` (median or mean) at every support size, and the notes
/// of LeARN's wins over the other methods.
fn series_of(
    curve: &LearningCurve,
    statistic: fn(&CurvePoint) -> f64,
) -> (Vec<CurveSeries>, Vec<Vec<String>>) {
    let sizes = &curve.config.support_sizes;
    let tasks = curve.test_tasks.len();
    let mut series = Vec::new();
    let mut notes = Vec::new();
    for method in CurveMethod::ALL {
        let points: Vec<&CurvePoint> = sizes
            .iter()
            .filter_map(|&n| {
                curve
                    .points
                    .iter()
                    .find(|p| p.method == method && p.support == n)
            })
            .collect();
        series.push(CurveSeries {
            label: method.label().to_string(),
            values: points.iter().map(|p| statistic(p)).collect(),
            dashed: method == CurveMethod::LearnUnadapted,
        });
        notes.push(
            points
                .iter()
                .map(|p| match method {
                    CurveMethod::Learn => String::new(),
                    _ => format!("LeARN lower on {}/{tasks}", p.learn_lower_on),
                })
                .collect(),
        );
    }
    (series, notes)
}

/// Adapted LeARN's medians, one series per meta-training seed.
fn seed_series(curve: &LearningCurve) -> Vec<CurveSeries> {
    curve
        .seed_spread
        .iter()
        .map(|seed| CurveSeries {
            label: format!("seed {}", seed.seed),
            values: seed.learn_median.clone(),
            dashed: false,
        })
        .collect()
}

/// The SVG and the Markdown of the curve.
fn render(curve: &LearningCurve, commit: &str) -> anyhow::Result<(String, String)> {
    let sizes = &curve.config.support_sizes;
    let tasks = curve.test_tasks.len();
    let (medians, notes) = series_of(curve, |p| p.median);
    let (means, _) = series_of(curve, |p| p.mean);
    let figure = CurveFigure {
        title: format!(
            "Duffing family: generalisation MSE on {tasks} unseen draws vs support samples"
        ),
        x_label: "support samples (first rows of each test task)".to_string(),
        y_label: "generalisation MSE (median over test tasks)".to_string(),
        samples: sizes.clone(),
        series: medians.clone(),
    };
    let config = &curve.config;
    let settings = match &config.learn_config {
        Some(path) => format!("the defaults with {} over them", path.display()),
        None => "the built-in defaults (the paper's settings)".to_string(),
    };
    let table = format!(
        "# LeARN on your own data: the worked example\n\n\
         Generated by `make own-data-example` (`learn own-data-example`) at commit {commit}: {} training and {tasks} unseen test tasks of the family of `experiments/own-data/example.json` (data seed {}), LeARN meta-trained with seed {} and {settings} in {:.1} s (final meta-loss {:.4}). Query: rows {}–{} of each test task; MSE over both states in the units of the targets.\n\n\
         **Declared before the first run:** {}\n\n\
         **Median generalisation MSE** over the {tasks} test tasks (the primary statistic; bold: lowest of the row; in brackets: on how many test tasks adapted LeARN's MSE is lower):\n\n{}\n\
         **Mean generalisation MSE** over the same tasks (a baseline that blows up on one task dominates it):\n\n{}\n\
         **Seed-to-seed spread of LeARN**: the median generalisation MSE of adapted LeARN meta-trained with each seed (the first is the seed of the tables above; the baselines have no seed):\n\n{}",
        config.training_tasks,
        config.data_seed,
        config.seed,
        curve.meta_training_seconds,
        curve.final_meta_loss,
        config.query_rows[0],
        config.query_rows[1] - 1,
        config.declared,
        curve_markdown(sizes, &medians, &notes, true),
        curve_markdown(sizes, &means, &[], true),
        curve_markdown(sizes, &seed_series(curve), &[], false),
    );
    Ok((figure.render_svg()?, table))
}
