//! `learn sindy --csv FILE [--csv FILE ...] --time t --state x,y [--control u] --library ...`:
//! fits a SINDy model on numeric CSV recordings (one trajectory per file), prints its equations,
//! optionally writes the model JSON; `learn sindy predict|simulate` apply a saved model
//! ([`super::sindy_apply`]).

use std::path::{Path, PathBuf};

use anyhow::{Context, anyhow, bail};
use data::{DEFAULT_UNIFORM_TOLERANCE, NumericStream, NumericTable, StreamedTimeAxis};
use sindy::{Derivative, DifferentiationError, UNIFORM_STEP_TOLERANCE};
use sindy::{
    FeatureLibrary, FitShape, LibrarySpec, Mat, OptimizerSpec, RowBlock, RowSource, Score,
    SindyError, SindyModel, SindyParams, Trajectory,
};

use output_set::{Existing, OutputSet};

use super::Global;
use super::sindy_apply::{self, ApplyCommand};

#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum OptimizerKind {
    /// Sequentially thresholded least squares (PySINDy's STLSQ).
    Stlsq,
    /// min ½‖Θξ − ẋ‖² + λ‖ξ‖₁, solved with clarabel.
    Lasso,
}

#[derive(clap::Args, Debug)]
#[command(args_conflicts_with_subcommands = true, subcommand_negates_reqs = true)]
pub struct Args {
    #[command(subcommand)]
    pub command: Option<ApplyCommand>,
    /// A numeric CSV file with a header row, a Parquet file (columns of numbers, known by its
    /// first bytes), or a PX4 ULog (`.ulg`, or a folder of its CSV export:
    /// columns `topic.field` on the clock of the first column's topic, or of the topic --time
    /// names; other topics' values held as of it); give --csv once per recording to fit several
    /// trajectories together (derivatives are estimated within each).
    #[arg(long, required = true)]
    pub csv: Vec<PathBuf>,
    /// The time column (strictly increasing; forward and central differences use the true time
    /// stamps, savgol needs uniform steps).
    #[arg(long, default_value = "t")]
    pub time: String,
    /// State columns, comma-separated (x in ẋ = f(x, u)).
    #[arg(long, value_delimiter = ',', required = true)]
    pub state: Vec<String>,
    /// Control columns, comma-separated (u).
    #[arg(long, value_delimiter = ',')]
    pub control: Vec<String>,
    #[command(flatten)]
    pub fit: FitArgs,
    /// Derivative estimator: forward, central, savgol or savgol:WINDOW:ORDER.
    #[arg(long, default_value = "central", value_parser = parse_derivative)]
    pub derivative: Derivative,
    /// Decimals printed in the equations (at most 17: an f64 has no more).
    #[arg(long, default_value_t = 3, value_parser = clap::value_parser!(u8).range(0..=17))]
    pub precision: u8,
    /// Write the model as JSON here (never overwrites an existing file without --force).
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Allow --out to replace an existing file.
    #[arg(long)]
    pub force: bool,
    /// Read the CSV in blocks of rows and fit as it is read, in memory that does not grow with
    /// the file (the default for one file over 8 MiB; one regular file with uniform time steps).
    #[arg(long)]
    pub stream: bool,
}

/// The library and optimizer of a SINDy fit (shared by `learn sindy` and `learn evaluate`).
#[derive(clap::Args, Debug)]
pub struct FitArgs {
    /// Library: parts joined by '+', each poly:D, poly:D:noconstant or fourier:K.
    #[arg(long, default_value = "poly:2")]
    pub library: String,
    /// Optimizer.
    #[arg(long, value_enum, default_value = "stlsq")]
    pub optimizer: OptimizerKind,
    /// STLSQ threshold; `None`: the default.
    #[arg(long, allow_hyphen_values = true,
          help = format!("STLSQ threshold (--optimizer stlsq only) [default: {DEFAULT_THRESHOLD}]"))]
    pub threshold: Option<f64>,
    /// STLSQ ridge strength; `None`: `sindy::DEFAULT_ALPHA`.
    #[arg(long, allow_hyphen_values = true,
          help = format!("STLSQ ridge strength (--optimizer stlsq only) [default: {}]",
                         sindy::DEFAULT_ALPHA))]
    pub alpha: Option<f64>,
    /// STLSQ iteration limit; `None`: `sindy::DEFAULT_MAX_ITER`.
    #[arg(long,
          help = format!("STLSQ iteration limit (--optimizer stlsq only) [default: {}]",
                         sindy::DEFAULT_MAX_ITER))]
    pub max_iter: Option<usize>,
    /// LASSO weight λ (required with --optimizer lasso).
    #[arg(long, allow_hyphen_values = true)]
    pub lambda: Option<f64>,
}

/// `--derivative`: a clap value parser, so that a setting with no derivative (`savgol:5:0`) or an
/// unbounded cost is a usage error before anything is read.
pub fn parse_derivative(text: &str) -> Result<Derivative, String> {
    Derivative::parse(text).map_err(|error| error.to_string())
}

/// The STLSQ threshold when --threshold is not given.
const DEFAULT_THRESHOLD: f64 = 0.1;

impl FitArgs {
    /// The library, checked.
    pub fn library(&self) -> anyhow::Result<FeatureLibrary> {
        Ok(FeatureLibrary::from_spec(&LibrarySpec::parse(
            &self.library,
        )?)?)
    }

    /// The optimizer, checked; flags of the other optimizer are refused.
    pub fn optimizer(&self) -> anyhow::Result<OptimizerSpec> {
        let optimizer = optimizer(self)?;
        optimizer.checked()?;
        Ok(optimizer)
    }
}

fn optimizer(args: &FitArgs) -> anyhow::Result<OptimizerSpec> {
    Ok(match args.optimizer {
        OptimizerKind::Stlsq => {
            if args.lambda.is_some() {
                bail!("--lambda applies to --optimizer lasso only");
            }
            OptimizerSpec::Stlsq {
                threshold: args.threshold.unwrap_or(DEFAULT_THRESHOLD),
                alpha: args.alpha.unwrap_or(sindy::DEFAULT_ALPHA),
                max_iter: args.max_iter.unwrap_or(sindy::DEFAULT_MAX_ITER),
            }
        }
        OptimizerKind::Lasso => {
            // Flags of the other optimizer would be ignored: refused, named.
            let stlsq_only: Vec<&str> = [
                ("--threshold", args.threshold.is_some()),
                ("--alpha", args.alpha.is_some()),
                ("--max-iter", args.max_iter.is_some()),
            ]
            .into_iter()
            .filter_map(|(flag, given)| given.then_some(flag))
            .collect();
            if !stlsq_only.is_empty() {
                bail!(
                    "{} {} to --optimizer stlsq only, not lasso",
                    stlsq_only.join(", "),
                    if stlsq_only.len() == 1 {
                        "applies"
                    } else {
                        "apply"
                    }
                );
            }
            OptimizerSpec::Lasso {
                lambda: args.lambda.context("--optimizer lasso needs --lambda L")?,
            }
        }
    })
}

/// CSV files larger than this are read in blocks of rows and fitted as they are read
/// ([`SindyParams::fit_streamed`]): memory then does not grow with the file.
pub const STREAM_ABOVE_BYTES: u64 = 8 << 20;

/// Rows per block read from a streamed CSV.
const STREAM_BLOCK_ROWS: usize = 1 << 14;

/// Blocks a streamed CSV is read ahead of the fit, per fitting thread: about one batch of the
/// segments the fit reduces at once (two blocks per thread), parsed while the batch before it is
/// reduced (a few MiB per thread).
const STREAM_BLOCKS_AHEAD_PER_THREAD: usize = 2;

/// One recording read whole: its trajectory and the line of the file each row starts on.
pub(super) struct Recording {
    pub(super) path: PathBuf,
    pub(super) trajectory: Trajectory,
    pub(super) table: NumericTable,
}

/// Reads the time column and `columns` (states, then controls) of `path` as a trajectory whose
/// derivatives `derivative` can be estimated (a savgol derivative needs uniform steps).
pub(super) fn read_recording(
    path: &Path,
    time_column: &str,
    state_count: usize,
    columns: &[&str],
    derivative: Derivative,
) -> anyhow::Result<Recording> {
    let (time, table) = if is_px4_log(path) {
        read_ulog_columns(path, time_column, columns)?
    } else {
        NumericTable::read_with_increasing_time(path, time_column, columns)?
    };
    check_sampling(path, time_column, derivative, &time, |row| table.line(row))?;
    let n = table.rows();
    let states = Mat::from_fn(n, state_count, |i, j| table.columns[j][i]);
    let controls = Mat::from_fn(n, columns.len() - state_count, |i, j| {
        table.columns[state_count + j][i]
    });
    let trajectory = Trajectory::new(time, states)?.with_controls(controls)?;
    Ok(Recording {
        path: path.to_path_buf(),
        trajectory,
        table,
    })
}

/// Whether `path` is read as a PX4 log: a `.ulg`, or a folder holding its CSV export.
fn is_px4_log(path: &Path) -> bool {
    data::layout::is_ulog(path) || path.is_dir()
}

/// The columns (`topic.field`) of a ULog, or of a folder holding its CSV export (one file per
/// topic), on the clock of `--time` when it names a topic (of the first column's topic while it
/// is the default `t`); says which columns were held, and how long.
fn read_ulog_columns(
    path: &Path,
    time_column: &str,
    columns: &[&str],
) -> anyhow::Result<(Vec<f64>, NumericTable)> {
    let base = (time_column != "t").then_some(time_column);
    let aligned = if path.is_dir() {
        data::ulog::aligned_export_table(path, base, columns)?.0
    } else {
        let log = ulog::Log::read(path)?;
        data::ulog::aligned_table(&log, path, base, columns)?
    };
    say!(
        "{}: {} rows on the clock of {}",
        path.display(),
        aligned.time.len(),
        aligned.base
    );
    for held in &aligned.held {
        say!(
            "  {} held from its {:.1} Hz samples (at most {:.3} s)",
            held.column,
            held.median_rate_hz,
            held.longest_hold_s
        );
    }
    Ok((aligned.time, aligned.table))
}

/// Refuses a time axis the derivative cannot use, naming the file's line.
fn check_sampling(
    path: &Path,
    time_column: &str,
    derivative: Derivative,
    time: &[f64],
    line: impl Fn(usize) -> usize,
) -> anyhow::Result<()> {
    derivative.check_times(time).map_err(|error| match error {
        DifferentiationError::NonUniformTime {
            sample, step, mean, ..
        } => anyhow!(
            "{}:{}:{time_column}: a step of {step} s against a mean of {mean} s: the \
             {derivative} derivative needs uniform samples (--derivative forward or central use \
             the true time stamps)",
            path.display(),
            line(sample),
        ),
        DifferentiationError::TooFewSamples { samples, .. } => {
            too_few_rows(&path.display().to_string(), samples, derivative)
        }
        other => anyhow!("{}: {other}", path.display()),
    })
}

/// A recording shorter than the derivative's stencil.
fn too_few_rows(files: &str, rows: usize, derivative: Derivative) -> anyhow::Error {
    anyhow!(
        "{files}: {rows} data rows, too few: the {derivative} estimator needs at least {} (its \
         window)",
        derivative.min_samples()
    )
}

/// The fit of the files read whole, one trajectory each; its model, score on all rows and number
/// of rows.
fn fit_whole(
    args: &Args,
    params: &SindyParams,
    columns: &[&str],
    feature_count: usize,
) -> anyhow::Result<(SindyModel, Score, usize)> {
    let derivative = args.derivative;
    let recordings = args
        .csv
        .iter()
        .map(|path| read_recording(path, &args.time, args.state.len(), columns, derivative))
        .collect::<anyhow::Result<Vec<_>>>()?;
    let n = recordings.iter().map(|r| r.table.rows()).sum();
    check_rows(args, n, feature_count, columns)?;
    check_memory(args, n, feature_count, RowSource::Whole)?;
    // The trajectories are fitted together; each file's table still names the lines of its rows.
    let (trajectories, sources): (Vec<Trajectory>, Vec<(PathBuf, NumericTable)>) = recordings
        .into_iter()
        .map(|r| (r.trajectory, (r.path, r.table)))
        .unzip();
    let model = params
        .fit(&trajectories)
        .map_err(|error| whole_fit_error(args, &sources, error))?;
    let score = model.score_all(&trajectories)?;
    Ok((model, score, n))
}

/// A fit's error over stacked recordings: a non-finite value named by its file and line.
fn whole_fit_error(
    args: &Args,
    sources: &[(PathBuf, NumericTable)],
    error: SindyError,
) -> anyhow::Error {
    let SindyError::NonFinite {
        what,
        row,
        column,
        value,
    } = error
    else {
        return fit_error(args, &args.csv[0], error, |row| row);
    };
    let mut first = 0;
    for (path, table) in sources {
        let rows = table.rows();
        if row < first + rows {
            let local = SindyError::NonFinite {
                what,
                row: row - first,
                column,
                value,
            };
            return fit_error(args, path, local, |row| table.line(row));
        }
        first += rows;
    }
    let error = SindyError::NonFinite {
        what,
        row,
        column,
        value,
    };
    fit_error(args, &args.csv[0], error, |row| row)
}

/// The fit of a file read in two passes of blocks: the time column (checked as a uniform axis),
/// then the rows, fitted as they come.
fn fit_streamed(
    args: &Args,
    params: &SindyParams,
    columns: &[&str],
    feature_count: usize,
) -> anyhow::Result<(SindyModel, Score, usize)> {
    let [csv] = args.csv.as_slice() else {
        bail!(
            "--stream reads one --csv file; {} were given (several recordings are read whole)",
            args.csv.len()
        );
    };
    // Savitzky–Golay takes steps within 1 % of the reference as even; the differences take any.
    let (tolerance, stamps_allowed) = match args.derivative {
        Derivative::SavitzkyGolay { .. } => (DEFAULT_UNIFORM_TOLERANCE, false),
        Derivative::Forward | Derivative::Central => (f64::INFINITY, true),
    };
    let ahead = STREAM_BLOCKS_AHEAD_PER_THREAD * evaluation::worker_threads();
    let mut stream =
        NumericStream::open(csv, &[args.time.as_str()])?.read_ahead(STREAM_BLOCK_ROWS, ahead);
    let mut axis = StreamedTimeAxis::new(csv, &args.time, tolerance);
    while let Some(block) = stream.next_block()? {
        axis.push(&block.columns[0], &block.lines)
            .map_err(|error| streamed_time_error(args.derivative, error))?;
    }
    let (smallest, largest) = axis.step_range().unwrap_or((0.0, 0.0));
    let (n, dt) = axis
        .finish()
        .map_err(|error| streamed_time_error(args.derivative, error))?;
    check_rows(args, n, feature_count, columns)?;
    check_memory(args, n, feature_count, RowSource::Streamed)?;
    // Uneven steps: the time column is read again with the rows, and the differences use it.
    let uneven = (largest - dt).max(dt - smallest) > UNIFORM_STEP_TOLERANCE * dt;
    let stamped = stamps_allowed && uneven;
    let mut names = Vec::with_capacity(columns.len() + 1);
    if stamped {
        names.push(args.time.as_str());
    }
    names.extend_from_slice(columns);
    let fit = params
        .fit_streamed(n, dt, || {
            let mut stream = NumericStream::open(csv, &names)
                .map_err(|error| SindyError::Source(Box::new(error)))?
                .read_ahead(STREAM_BLOCK_ROWS, ahead);
            Ok(move || {
                let block = stream
                    .next_block()
                    .map_err(|error| SindyError::Source(Box::new(error)))?;
                Ok(block.map(|mut block| {
                    let time = stamped.then(|| block.columns.remove(0));
                    RowBlock {
                        columns: block.columns,
                        time,
                    }
                }))
            })
        })
        .map_err(|error| {
            fit_error(args, csv, error, |row| {
                NumericStream::line_of_row(csv, row).unwrap_or(row + 2)
            })
        })?;
    Ok((fit.model, fit.score, n))
}

/// A time column a fit read in blocks cannot use; uneven steps (refused for Savitzky–Golay only)
/// are named as such.
fn streamed_time_error(derivative: Derivative, error: data::DataError) -> anyhow::Error {
    match error {
        data::DataError::NonUniformSampling { .. } => anyhow!(
            "{error} (the {derivative} derivative needs even time steps; forward and central take \
             any)"
        ),
        other => other.into(),
    }
}

fn check_rows(args: &Args, n: usize, feature_count: usize, columns: &[&str]) -> anyhow::Result<()> {
    if n < args.derivative.min_samples() {
        return Err(too_few_rows(&files(&args.csv), n, args.derivative));
    }
    if n < feature_count {
        bail!(
            "{}: {n} data rows, fewer than the {feature_count} features of library {} on {}: \
             the fit needs at least one row per feature",
            files(&args.csv),
            args.fit.library,
            columns.join(", ")
        );
    }
    Ok(())
}

/// The files named in a message: one path, or the paths joined by ", ".
fn files(paths: &[PathBuf]) -> String {
    paths
        .iter()
        .map(|path| path.display().to_string())
        .collect::<Vec<_>>()
        .join(", ")
}

/// Refuses a fit whose estimated peak memory ([`FitShape::peak_bytes`]) exceeds what the process
/// may still allocate ([`super::memory::memory_bound`]), before any of it is allocated.
fn check_memory(
    args: &Args,
    rows: usize,
    feature_count: usize,
    source: RowSource,
) -> anyhow::Result<()> {
    let threads = evaluation::worker_threads();
    let shape = FitShape {
        rows,
        features: feature_count,
        targets: args.state.len(),
        source,
        threads,
    };
    let needed = shape.peak_bytes(&args.fit.optimizer()?);
    let Some(bound) = super::memory::memory_bound(threads) else {
        return Ok(());
    };
    if needed > bound.bytes {
        bail!(
            "{}: a fit of {rows} rows on the {feature_count} features of library {} needs about \
             {} of memory, more than {} ({}): use a smaller library or fewer states",
            files(&args.csv),
            args.fit.library,
            super::memory::in_words(needed),
            bound.source,
            super::memory::in_words(bound.bytes),
        );
    }
    Ok(())
}

/// A fit's error, a non-finite value named by the line of its row in `path`.
fn fit_error(
    args: &Args,
    path: &Path,
    error: SindyError,
    line: impl Fn(usize) -> usize,
) -> anyhow::Error {
    match error {
        SindyError::NonFinite {
            what,
            row,
            column,
            value,
        } => {
            let hint = if what == "library" {
                format!(" (values too large for library {}?)", args.fit.library)
            } else {
                String::new()
            };
            anyhow!(
                "{}:{}: {column} is not finite ({value}) on this row{hint}",
                path.display(),
                line(row),
            )
        }
        // The file's own error (a bad line met while the rows were read), as the whole-file read
        // gives it: it names the file already.
        SindyError::Source(source) => anyhow::Error::from_boxed(source),
        other => anyhow::Error::new(other).context(format!("fitting {}", files(&args.csv))),
    }
}

pub fn run(global: &Global, args: Args) -> anyhow::Result<()> {
    if let Some(command) = args.command {
        return sindy_apply::run(global, command);
    }
    // Everything that can be checked without reading the file is checked first.
    let library = args.fit.library()?;
    let optimizer = args.fit.optimizer()?;
    let derivative = args.derivative;
    let columns: Vec<&str> = args
        .state
        .iter()
        .chain(&args.control)
        .map(String::as_str)
        .collect();
    for (i, name) in columns.iter().enumerate() {
        let flag = if i < args.state.len() {
            "--state"
        } else {
            "--control"
        };
        if name.is_empty() {
            bail!("{flag}: empty column name");
        }
        if columns[..i].contains(name) {
            bail!("{flag}: column '{name}' is named twice among --state and --control");
        }
    }
    let feature_count = library.unique_feature_names(&columns)?.len();
    // The model file is checked and staged (its folder proven writable) before the CSV is read.
    let output = match &args.out {
        Some(out) => {
            let mut set = OutputSet::new("sindy");
            for csv in &args.csv {
                set.input("the --csv input", csv);
            }
            let file = set.file(out, "--out", Existing::from_force(args.force));
            Some((set.prepare()?, file))
        }
        None => None,
    };

    let state_names: Vec<&str> = args.state.iter().map(String::as_str).collect();
    let control_names: Vec<&str> = args.control.iter().map(String::as_str).collect();
    let params = SindyParams::new(&state_names, &control_names)
        .library(library)
        .optimizer(optimizer)
        .derivative(derivative);
    if args.stream && args.csv.iter().any(|path| is_px4_log(path)) {
        bail!("--stream reads a CSV; a ULog or a folder of its CSV export is read whole");
    }
    let streamed = args.stream
        || (args.csv.len() == 1
            && !data::layout::is_ulog(&args.csv[0])
            && std::fs::metadata(&args.csv[0])
                .is_ok_and(|metadata| metadata.is_file() && metadata.len() > STREAM_ABOVE_BYTES));
    let (model, score, n) = if streamed {
        fit_streamed(&args, &params, &columns, feature_count)?
    } else {
        fit_whole(&args, &params, &columns, feature_count)?
    };
    // Finite inputs can still give an unusable fit (e.g. time steps so small that the derivative
    // estimates overflow): an error, not equations and a score of inf or NaN.
    if !(score.mse.is_finite() && (score.r2.is_finite() || !score.r2_defined())) {
        bail!(
            "{}: the fit is not finite (MSE {}, R² {}): are the time steps of column '{}' in \
             seconds?",
            files(&args.csv),
            score.mse,
            score.r2,
            args.time
        );
    }
    // Files first, then words: an unwritable terminal never stops the model from being written.
    if let Some((staged, file)) = output {
        super::staged_write(&staged, || model.save(staged.path(file), true))?;
        staged.commit()?;
    }
    for line in model.equations(usize::from(args.precision)) {
        say!("{line}");
    }
    let trajectories = match args.csv.len() {
        1 => String::new(),
        count => format!(" in {count} trajectories"),
    };
    note!(
        "{n} samples{trajectories}, {} features; MSE {:.6}, {}",
        model.feature_names().len(),
        score.mse,
        r2_text(&model, &score),
    );
    if let Some(out) = &args.out {
        note!("model written to {}", out.display());
    }
    Ok(())
}

/// R² as printed: R² divides by the variance of the target, so on a constant one it is rounding
/// noise; such states are left out of it and named.
pub(super) fn r2_text(model: &SindyModel, score: &Score) -> String {
    let states = model.state_names();
    let constant: Vec<String> = score
        .constant_states
        .iter()
        .map(|&j| format!("{}'", states[j]))
        .collect();
    match score.r2_varying {
        _ if constant.is_empty() => format!("R² {:.6}", score.r2),
        Some(r2) => format!(
            "R² {r2:.6} over the {} of {} states whose target varies ({} constant: no R²)",
            states.len() - constant.len(),
            states.len(),
            constant.join(", ")
        ),
        None => "R² n/a (constant target)".to_string(),
    }
}
