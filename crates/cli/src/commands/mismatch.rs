//! `learn mismatch`: locate, name and fit the physics a nominal model leaves out.
//!
//! - `--recording REAL.csv --model NOMINAL.json --out DIR`: one recording → DIR/mismatch.{json,svg,md}.
//! - `--demo MANIFEST --out DIR`: simulate every case of the manifest with a concealed effect, run
//!   the analysis blind on each, and write DIR/summary.{md,json}.
//! - `--flights CONDITIONS.json --model NOMINAL.json --out DIR`: every wind condition's evaluation
//!   flight of the data directory → DIR/<condition>/… and DIR/neural-fly.md.

use std::path::{Path, PathBuf};

use anyhow::bail;

use super::Global;

#[derive(clap::Args, Debug)]
pub struct Args {
    /// A recording in the Neural-Fly CSV layout.
    #[arg(long, conflicts_with_all = ["demo", "flights"])]
    pub recording: Option<PathBuf>,
    /// The nominal model JSON (not with --demo: each scenario names its own model).
    #[arg(long, conflicts_with = "demo")]
    pub model: Option<PathBuf>,
    /// Output directory.
    #[arg(long)]
    pub out: PathBuf,
    /// A demo manifest: simulated cases with concealed effects.
    #[arg(long, conflicts_with = "flights")]
    pub demo: Option<PathBuf>,
    /// Where the demo writes its simulated recordings and per-case outputs.
    #[arg(long, default_value = "target/mismatch-demo")]
    pub work: PathBuf,
    /// The experiment's conditions file: analyse the evaluation flights of every wind condition.
    #[arg(long)]
    pub flights: Option<PathBuf>,
    /// Overwrite existing output files.
    #[arg(long)]
    pub force: bool,
}

pub fn run(global: &Global, args: Args) -> anyhow::Result<()> {
    if let Some(manifest) = &args.demo {
        let summary = mismatch::demo::run_demo(manifest, &args.work, &args.out, args.force)?;
        print!("{}", summary.table_text());
        println!("wrote {}", args.out.join("summary.md").display());
        return Ok(());
    }
    let Some(model_path) = &args.model else {
        bail!("--model is required with --recording or --flights");
    };
    // No output file may be one of the inputs, even with --force.
    let inputs = [
        ("--model", model_path.as_path()),
        (
            "--recording",
            args.recording.as_deref().unwrap_or(Path::new("")),
        ),
        (
            "--flights",
            args.flights.as_deref().unwrap_or(Path::new("")),
        ),
    ];
    for output in mismatch::output_paths(&args.out)
        .iter()
        .chain([&args.out.join("neural-fly.md")])
    {
        super::refuse_input_as_output(output, &inputs)?;
    }
    let model = physics::NominalModel::load(model_path)?;
    if let Some(conditions) = &args.flights {
        let data_dir = global.data_dir()?;
        let lines = mismatch::flights::run_flights(
            conditions,
            &data_dir,
            &model,
            &model_path.display().to_string(),
            &args.out,
            args.force,
        )?;
        for line in lines {
            println!("{line}");
        }
        return Ok(());
    }
    let Some(recording) = &args.recording else {
        bail!("give --recording (or --demo, or --flights)");
    };
    mismatch::check_outputs(&args.out, args.force)?;
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
