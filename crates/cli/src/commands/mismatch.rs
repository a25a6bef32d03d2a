//! `learn mismatch`: locate, name and fit the physics a nominal model leaves out.
//!
//! - `--recording REAL.csv --model NOMINAL.json --out DIR [--rows A:B]`: one recording (or its data
//!   rows A:B) → DIR/mismatch.{json,svg,md}; the analysis's stages shown on a terminal.
//! - `--demo MANIFEST --out DIR [--work WORK]`: simulate every case of the manifest with a concealed
//!   effect (`WORK/<case>/recording.csv`), run the analysis blind on each (`WORK/<case>/mismatch.*`),
//!   and write DIR/summary.{md,json}.
//! - `--flights CONDITIONS.json --model NOMINAL.json --out DIR`: every flight of every condition of
//!   the data directory analysed together (one vehicle, one air velocity per flight) →
//!   `DIR/<model stem>.{json,md,svg}`.
//!
//! Every mode plans every file it will write in an output set (the `outputs` crate) and checks
//! them all before any work: none may be one of the files the run reads (even with `--force`),
//! each folder is proven writable and locked, and an existing file is replaced only when this
//! command wrote it and `--force` is given. The results are staged and moved into place at the end.

use std::path::{Path, PathBuf};

use outputs::{Existing, OutputSet};

use super::Global;

#[derive(clap::Args, Debug)]
#[command(group(
    clap::ArgGroup::new("mode")
        .required(true)
        .args(["recording", "demo", "flights"])
))]
pub struct Args {
    /// A recording in the Neural-Fly CSV layout.
    #[arg(long, conflicts_with_all = ["demo", "flights"])]
    pub recording: Option<PathBuf>,
    /// The nominal model JSON (with --recording or --flights; not with --demo: each scenario names
    /// its own model).
    #[arg(long, conflicts_with = "demo", required_unless_present = "demo")]
    pub model: Option<PathBuf>,
    /// Output directory.
    #[arg(long)]
    pub out: PathBuf,
    /// A demo manifest: simulated cases with concealed effects.
    #[arg(long, conflicts_with = "flights")]
    pub demo: Option<PathBuf>,
    /// With --demo: where it writes each case's simulated recording and analysis
    /// (WORK/CASE/recording.csv, mismatch.{json,svg,md}; default: target/mismatch-demo);
    /// existing ones are replaced only with --force.
    #[arg(long, conflicts_with_all = ["recording", "flights"])]
    pub work: Option<PathBuf>,
    /// The experiment's conditions file: analyse every controller's flight at every condition
    /// together (one vehicle, one air velocity per flight; conditions marked calm calibrate).
    #[arg(long)]
    pub flights: Option<PathBuf>,
    /// With --recording: analyse only data rows A:B (counted from 0, B excluded), e.g. a part of a
    /// recording longer than one analysis accepts.
    #[arg(long, value_parser = super::evaluate::parse_rows, requires = "recording")]
    pub rows: Option<std::ops::Range<usize>>,
    /// Overwrite existing output files (never one of the run's inputs).
    #[arg(long)]
    pub force: bool,
}

pub fn run(global: &Global, args: Args) -> anyhow::Result<()> {
    // clap's "mode" group gives exactly one of --recording, --demo and --flights, and --model
    // with the two that need it; the last arm only keeps the match total.
    match (&args.recording, &args.demo, &args.flights, &args.model) {
        (None, Some(manifest), None, None) => run_demo(manifest, &args),
        (None, None, Some(conditions), Some(model)) => {
            run_flights(global, conditions, model, &args)
        }
        (Some(recording), None, None, Some(model)) => {
            run_recording(global, recording, model, &args)
        }
        _ => anyhow::bail!(
            "give one of --recording or --flights (each with --model), or --demo (without --model)"
        ),
    }
}

/// Where the demo writes its cases without `--work`.
const DEFAULT_WORK: &str = "target/mismatch-demo";

/// A nominal model under the project's JSON policy (bounded, BOM accepted, no key twice).
fn load_model(path: &Path) -> anyhow::Result<physics::NominalModel> {
    let text = super::read_policy_json(path)?;
    Ok(physics::NominalModel::from_json(&text, path)?)
}

/// The name of `path` relative to `dir` (its file name when it is not below it).
fn relative_to(path: &Path, dir: &Path) -> PathBuf {
    path.strip_prefix(dir)
        .map(Path::to_path_buf)
        .unwrap_or_else(|_| path.file_name().map(PathBuf::from).unwrap_or_default())
}

/// The demo: its summary (`--out`) is an output set; the cases' files in `--work` are a scratch
/// of intermediate files (recordings, per-case analyses naming their paths), written in place
/// after the same checks as before any work.
fn run_demo(manifest: &Path, args: &Args) -> anyhow::Result<()> {
    let work = args.work.as_deref().unwrap_or(Path::new(DEFAULT_WORK));
    let plan = mismatch::demo::DemoPlan::load(manifest, work, &args.out)?;
    plan.check_outputs(args.force)?;
    let mut set = OutputSet::new("mismatch --demo");
    for (what, path) in plan.inputs() {
        set.input(what, path);
    }
    let out = set.folder(&args.out, "--out", Existing::from_force(args.force));
    for path in plan.summary_paths() {
        set.file_in(out, relative_to(&path, &args.out));
    }
    let staged = set.prepare()?;
    let staged_plan = plan.with_out(staged.dir(out));
    let summary = super::staged_write(&staged, || staged_plan.run(args.force))?;
    staged.commit()?;
    say_part!("{}", summary.view().table_text());
    say!("wrote {}", plan.summary_paths()[0].display());
    Ok(())
}

fn run_flights(
    global: &Global,
    conditions: &Path,
    model_path: &Path,
    args: &Args,
) -> anyhow::Result<()> {
    let data_dir = global.data_dir()?;
    let plan = mismatch::fleet::FleetPlan::load(conditions, &data_dir, model_path, &args.out)?;
    let stem = model_path
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    let mut set = OutputSet::new(format!("mismatch --flights --model {stem}"));
    for (what, path) in plan.inputs() {
        set.input(what, path);
    }
    set.input("the --model file", model_path);
    let out = set.folder(&args.out, "--out", Existing::from_force(args.force));
    for path in plan.outputs() {
        set.file_in(out, relative_to(&path, &args.out));
    }
    set.check()?;
    let model = load_model(model_path)?;
    let staged = set.prepare()?;
    let staged_plan =
        mismatch::fleet::FleetPlan::load(conditions, &data_dir, model_path, staged.dir(out))?;
    let (_, lines) = super::staged_write(&staged, || {
        staged_plan.run(&model, &model_path.display().to_string(), true)
    })?;
    staged.commit()?;
    for line in lines {
        say!("{line}");
    }
    // The files by their final names (the run wrote them in the staging folder).
    for path in plan.outputs() {
        say!("wrote {}", path.display());
    }
    Ok(())
}

/// The recording, or the rows of it that `--rows` asks for.
fn read_recording(
    recording: &Path,
    rows: Option<&std::ops::Range<usize>>,
) -> anyhow::Result<data::FlightLog> {
    let log = data::FlightLog::read(recording)?;
    let Some(rows) = rows else {
        return Ok(log);
    };
    log.row_range(rows.clone()).ok_or_else(|| {
        anyhow::anyhow!(
            "{}: --rows {}:{} reaches past its {} data rows",
            recording.display(),
            rows.start,
            rows.end,
            log.len()
        )
    })
}

fn run_recording(
    global: &Global,
    recording: &Path,
    model_path: &Path,
    args: &Args,
) -> anyhow::Result<()> {
    let mut set = OutputSet::new("mismatch --recording");
    set.input("the --model file", model_path);
    set.input("the --recording", recording);
    let out = set.folder(&args.out, "--out", Existing::from_force(args.force));
    for path in mismatch::output_paths(Path::new("")) {
        set.file_in(out, path);
    }
    set.check()?;
    let model = load_model(model_path)?;
    let staged = set.prepare()?;
    let log = read_recording(recording, args.rows.as_ref())?;
    let spinner = super::progress::spinner(global.show_progress(), "preparing the recording");
    let analysis = mismatch::analyze_observed(
        &log,
        &model,
        &model_path.display().to_string(),
        &mismatch::AnalysisSettings::default(),
        &|pass, stage| spinner.set_message(format!("pass {pass}: {}", stage.describe())),
    );
    spinner.finish_and_clear();
    let analysis = analysis?;
    super::staged_write(&staged, || {
        mismatch::write_outputs(&analysis, staged.dir(out), true)
    })?;
    staged.commit()?;
    let report = &analysis.report;
    let names: Vec<&str> = report.effects.iter().map(|e| e.id.name()).collect();
    say!(
        "effects: {}; held-out MSE {:.5} -> {:.5}; wrote {}",
        if names.is_empty() {
            "none".to_string()
        } else {
            names.join(", ")
        },
        report.fit.heldout.before.mse,
        report.fit.heldout.after.mse,
        args.out.display()
    );
    Ok(())
}
