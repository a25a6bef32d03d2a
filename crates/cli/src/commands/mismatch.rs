//! `learn mismatch`: locate, name and fit the physics a nominal model leaves out.
//!
//! - `--recording REAL.csv --model NOMINAL.json --out DIR`: one recording → DIR/mismatch.{json,svg,md}.
//! - `--demo MANIFEST --out DIR [--work WORK]`: simulate every case of the manifest with a concealed
//!   effect (WORK/<case>/recording.csv), run the analysis blind on each (WORK/<case>/mismatch.*),
//!   and write DIR/summary.{md,json}.
//! - `--flights CONDITIONS.json --model NOMINAL.json --out DIR`: every flight of every condition of
//!   the data directory analysed together (one vehicle, one air velocity per flight) →
//!   DIR/<model stem>.{json,md,svg}.
//!
//! Every mode works out every file it will write and checks them all before any work: none may be
//! one of the files the run reads (even with `--force`), each must be writable, and none may exist
//! unless `--force` is given.

use std::path::{Path, PathBuf};

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
    /// (WORK/<case>/recording.csv, mismatch.{json,svg,md}; default: target/mismatch-demo);
    /// existing ones are replaced only with --force.
    #[arg(long, conflicts_with_all = ["recording", "flights"])]
    pub work: Option<PathBuf>,
    /// The experiment's conditions file: analyse every controller's flight at every condition
    /// together (one vehicle, one air velocity per flight; conditions marked calm calibrate).
    #[arg(long)]
    pub flights: Option<PathBuf>,
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
        (Some(recording), None, None, Some(model)) => run_recording(recording, model, &args),
        _ => anyhow::bail!(
            "give one of --recording or --flights (each with --model), or --demo (without --model)"
        ),
    }
}

/// Where the demo writes its cases without `--work`.
const DEFAULT_WORK: &str = "target/mismatch-demo";

fn run_demo(manifest: &Path, args: &Args) -> anyhow::Result<()> {
    let work = args.work.as_deref().unwrap_or(Path::new(DEFAULT_WORK));
    super::refuse_unwritable_dir(&args.out, "--out")?;
    super::refuse_unwritable_dir(work, "--work")?;
    let plan = mismatch::demo::DemoPlan::load(manifest, work, &args.out)?;
    plan.check_outputs(args.force)?;
    let summary = plan.run(args.force)?;
    print!("{}", summary.table_text());
    println!("wrote {}", plan.summary_paths()[0].display());
    Ok(())
}

fn run_flights(
    global: &Global,
    conditions: &Path,
    model_path: &Path,
    args: &Args,
) -> anyhow::Result<()> {
    super::refuse_unwritable_dir(&args.out, "--out")?;
    let data_dir = global.data_dir()?;
    let plan = mismatch::fleet::FleetPlan::load(conditions, &data_dir, model_path, &args.out)?;
    plan.check_outputs(model_path, args.force)?;
    let model = physics::NominalModel::load(model_path)?;
    let (_, lines) = plan.run(&model, &model_path.display().to_string(), args.force)?;
    for line in lines {
        println!("{line}");
    }
    Ok(())
}

fn run_recording(recording: &Path, model_path: &Path, args: &Args) -> anyhow::Result<()> {
    super::refuse_unwritable_dir(&args.out, "--out")?;
    let inputs = [
        ("the --model file".to_string(), model_path.to_path_buf()),
        ("the --recording".to_string(), recording.to_path_buf()),
    ];
    let outputs: Vec<(PathBuf, &str)> = mismatch::output_paths(&args.out)
        .into_iter()
        .map(|p| (p, "--out"))
        .collect();
    mismatch::check_run_outputs(&outputs, &inputs, args.force)?;
    let model = physics::NominalModel::load(model_path)?;
    let log = data::FlightLog::read(recording)?;
    let analysis = mismatch::analyze(
        &log,
        &model,
        &model_path.display().to_string(),
        &mismatch::AnalysisSettings::default(),
    )?;
    mismatch::write_outputs(&analysis, &args.out, args.force)?;
    let report = &analysis.report;
    let names: Vec<&str> = report.effects.iter().map(|e| e.id.as_str()).collect();
    println!(
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
