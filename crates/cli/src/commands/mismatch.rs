//! `learn mismatch`: locate, name and fit the physics a nominal model leaves out.
//!
//! - `--recording REAL.csv --model NOMINAL.json --out DIR [--rows A:B] [--part-rows N]`: one
//!   recording (or its data rows A:B) → DIR/mismatch.{json,svg,md}; one longer than N rows (40,000
//!   by default, the most one analysis takes) is analysed in consecutive parts and those files
//!   summarise them; the analysis's stages shown on a terminal.
//! - `--demo MANIFEST --out DIR [--work WORK]`: simulate every case of the manifest with a concealed
//!   effect (`WORK/<case>/recording.csv`), run the analysis blind on each (`WORK/<case>/mismatch.*`),
//!   and write DIR/summary.{md,json}.
//! - `--flights CONDITIONS.json --model NOMINAL.json --out DIR`: every flight of every condition of
//!   the data directory analysed together (one vehicle, one air velocity per flight) →
//!   `DIR/<model stem>.{json,md,svg}`.
//!
//! Every mode plans every file it will write in an output set (the `output_set` crate) and checks
//! them all before any work: none may be one of the files the run reads (even with `--force`),
//! each folder is proven writable and locked, and an existing file is replaced only when this
//! command wrote it and `--force` is given. The results are staged and moved into place at the end.

use std::path::{Path, PathBuf};

use mismatch::ANALYSIS_FILES;
use mismatch::demo::SUMMARY_FILES;
use output_set::{Existing, OutputSet};

use super::Global;

#[derive(clap::Args, Debug)]
#[command(group(
    clap::ArgGroup::new("mode")
        .required(true)
        .args(["recording", "demo", "flights"])
))]
pub struct Args {
    /// A recording: in the Neural-Fly CSV layout, or a CSV file, PX4 ULog or folder of a PX4 CSV
    /// export that --layout describes.
    #[arg(long, conflicts_with_all = ["demo", "flights"])]
    pub recording: Option<PathBuf>,
    /// With --recording: a layout description (JSON) saying which columns or ULog topics hold the
    /// recording's time, position, velocity, attitude, body rate, motor commands and battery
    /// voltage, and in which units and frames (docs/layouts.md).
    #[arg(long, requires = "recording")]
    pub layout: Option<PathBuf>,
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
    /// With --recording: the most rows one analysis takes (1,250 to 40,000, the default); a longer
    /// recording is analysed in consecutive equal parts of at most this many rows, and its effects
    /// are those more than half of the parts name, their parameters pooled.
    #[arg(long, requires = "recording")]
    pub part_rows: Option<usize>,
    /// With --recording: half the support of the comparison's test function, s (default 0.2); it
    /// must span at least three sample intervals, so a log sampled slower than 15 Hz needs more.
    #[arg(long, requires = "recording")]
    pub half_width: Option<f64>,
    /// Overwrite existing output files (never one of the run's inputs).
    #[arg(long)]
    pub force: bool,
}

pub fn run(global: &Global, args: Args) -> anyhow::Result<()> {
    // clap's "mode" group gives exactly one of --recording, --demo and --flights, and --model
    // with the two that need it; the last arm only keeps the match total.
    let mut settings = mismatch::Settings::default();
    if let Some(half_width) = args.half_width {
        settings.comparison.test_function.half_width_s = half_width;
    }
    let settings = settings.checked()?;
    match (&args.recording, &args.demo, &args.flights, &args.model) {
        (None, Some(manifest), None, None) => run_demo(manifest, &args, &settings),
        (None, None, Some(conditions), Some(model)) => {
            run_flights(global, conditions, model, &args, &settings)
        }
        (Some(recording), None, None, Some(model)) => {
            run_recording(global, recording, model, &args, &settings)
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

/// Writes `contents` to `path`, creating its folders (never a staging folder an interrupt removed);
/// the error names the file.
fn write_file(path: &Path, contents: &str) -> mismatch::Result<()> {
    let io = |source| mismatch::MismatchError::Io {
        path: path.to_path_buf(),
        source,
    };
    output_set::create_parent_folders(path).map_err(io)?;
    std::fs::write(path, contents).map_err(io)
}

/// Writes each of `files` (its name, its contents) into `dir`.
fn write_files<N: AsRef<Path>>(
    dir: &Path,
    files: impl IntoIterator<Item = (N, String)>,
) -> mismatch::Result<()> {
    files
        .into_iter()
        .try_for_each(|(name, contents)| write_file(&dir.join(name), &contents))
}

/// The demo: its summary (`--out`) is an output set; the cases' files in `--work` are a scratch
/// of intermediate files (recordings, per-case analyses naming their paths), checked with the
/// summary before any work and written in place as each case ends.
fn run_demo(
    manifest: &Path,
    args: &Args,
    settings: &mismatch::CheckedSettings,
) -> anyhow::Result<()> {
    let work = args.work.as_deref().unwrap_or(Path::new(DEFAULT_WORK));
    let plan = mismatch::demo::DemoPlan::load(manifest, work)?;
    let existing = Existing::from_force(args.force);
    let mut every_file = OutputSet::new("mismatch --demo");
    for (what, path) in plan.inputs() {
        every_file.input(what, path);
    }
    for name in SUMMARY_FILES {
        every_file.file(args.out.join(name), "--out", existing);
    }
    for path in plan.case_outputs() {
        every_file.file(path, "--work", existing);
    }
    every_file.check()?;
    let mut set = OutputSet::new("mismatch --demo");
    for (what, path) in plan.inputs() {
        set.input(what, path);
    }
    let out = set.folder(&args.out, "--out", existing);
    for name in SUMMARY_FILES {
        set.file_in(out, name);
    }
    let staged = set.prepare()?;
    let summary = plan.run(&write_file, settings)?;
    super::staged_write(&staged, || {
        write_files(
            staged.dir(out),
            SUMMARY_FILES.into_iter().zip(summary.render(manifest)),
        )
    })?;
    staged.commit()?;
    say_part!("{}", summary.view(manifest).table_text());
    say!("wrote {}", args.out.join(SUMMARY_FILES[0]).display());
    Ok(())
}

fn run_flights(
    global: &Global,
    conditions: &Path,
    model_path: &Path,
    args: &Args,
    settings: &mismatch::CheckedSettings,
) -> anyhow::Result<()> {
    let data_dir = global.data_dir()?;
    let plan = mismatch::fleet::FleetPlan::load(conditions, &data_dir)?;
    let stem = model_path
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| "fleet".into());
    let names = mismatch::fleet::file_names(&stem);
    let mut set = OutputSet::new(format!("mismatch --flights --model {stem}"));
    for (what, path) in plan.inputs() {
        set.input(what, path);
    }
    set.input("the --model file", model_path);
    let out = set.folder(&args.out, "--out", Existing::from_force(args.force));
    for name in &names {
        set.file_in(out, name);
    }
    set.check()?;
    let model = load_model(model_path)?;
    let staged = set.prepare()?;
    let report = plan.run(&model, &model_path.display().to_string(), settings)?;
    super::staged_write(&staged, || {
        let dir = staged.dir(out);
        write_files(dir, names.iter().zip(report.render(dir, &stem)?))
    })?;
    staged.commit()?;
    for line in report.view().lines() {
        say!("{line}");
    }
    for name in &names {
        say!("wrote {}", args.out.join(name).display());
    }
    Ok(())
}

fn run_recording(
    global: &Global,
    recording: &Path,
    model_path: &Path,
    args: &Args,
    settings: &mismatch::CheckedSettings,
) -> anyhow::Result<()> {
    let part_rows = args
        .part_rows
        .unwrap_or(mismatch::recording::degenerate::MAX_ANALYSED_ROWS);
    mismatch::check_part_rows(part_rows)?;
    let mut set = OutputSet::new("mismatch --recording");
    set.input("the --model file", model_path);
    set.input("the --recording", recording);
    if let Some(layout) = &args.layout {
        set.input("the --layout file", layout);
    }
    let out = set.folder(&args.out, "--out", Existing::from_force(args.force));
    for name in ANALYSIS_FILES {
        set.file_in(out, name);
    }
    set.check()?;
    let model = load_model(model_path)?;
    let staged = set.prepare()?;
    let log = data::layout::read_recording(recording, args.layout.as_deref(), args.rows.clone())?;
    if log.len() > part_rows {
        let analysis = analyze_in_parts(global, &log, part_rows, (&model, model_path), settings)?;
        super::staged_write(&staged, || {
            let dir = staged.dir(out);
            write_files(dir, ANALYSIS_FILES.into_iter().zip(analysis.render(dir)?))
        })?;
        staged.commit()?;
        say_parts(&analysis, &args.out);
        return Ok(());
    }
    let spinner = super::progress::spinner(global.show_progress(), "preparing the recording");
    let analysis = mismatch::analyze_observed(
        &log,
        &model,
        &model_path.display().to_string(),
        settings,
        &|pass, stage| spinner.set_message(format!("pass {pass}: {}", stage.describe())),
    );
    spinner.finish_and_clear();
    let analysis = analysis?;
    super::staged_write(&staged, || {
        let dir = staged.dir(out);
        write_files(dir, ANALYSIS_FILES.into_iter().zip(analysis.render(dir)?))
    })?;
    staged.commit()?;
    let report = &analysis.report;
    let names: Vec<&str> = report.effects.iter().map(|e| e.id.name()).collect();
    let inseparable: String = report
        .not_separable
        .iter()
        .map(|n| format!(" ({} not separable from a stand-in)", n.effect.id.name()))
        .collect();
    say!(
        "effects: {}{inseparable}; held-out MSE {:.5} -> {:.5}; wrote {}",
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

/// A recording longer than `part_rows` rows, analysed in parts, each part's stage shown.
fn analyze_in_parts(
    global: &Global,
    log: &data::FlightLog,
    part_rows: usize,
    (model, model_path): (&physics::NominalModel, &Path),
    settings: &mismatch::CheckedSettings,
) -> anyhow::Result<mismatch::PartedAnalysis> {
    let parts = mismatch::part_ranges(log.len(), part_rows).len();
    let spinner = super::progress::spinner(
        global.show_progress(),
        &format!("{} rows in {parts} parts", log.len()),
    );
    let analysis = mismatch::analyze_in_parts(
        log,
        part_rows,
        model,
        &model_path.display().to_string(),
        settings,
        &|part, pass, stage| {
            spinner.set_message(format!(
                "part {} of {parts}, pass {pass}: {}",
                part + 1,
                stage.describe()
            ))
        },
    );
    spinner.finish_and_clear();
    Ok(analysis?)
}

/// The one line a long recording's analysis ends with.
fn say_parts(analysis: &mismatch::PartedAnalysis, out: &Path) {
    let parts = analysis.parts.len();
    let named: Vec<String> = analysis
        .effects
        .iter()
        .filter(|e| e.named)
        .map(|e| format!("{} ({} of {parts} parts)", e.id, e.named_in))
        .collect();
    let [before, after] = analysis.heldout;
    say!(
        "{} rows in {parts} parts; effects: {}; held-out MSE {before:.5} -> {after:.5} (mean over the parts); wrote {}",
        analysis.rows,
        if named.is_empty() {
            "none".to_string()
        } else {
            named.join(", ")
        },
        out.display()
    );
}
