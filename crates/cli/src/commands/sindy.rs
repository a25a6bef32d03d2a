//! `learn sindy --csv FILE --time t --state x,y [--control u] --library poly:2+fourier:1 ...`:
//! fits a SINDy model on any numeric CSV, prints its equations, optionally writes the model JSON.

use std::path::PathBuf;

use anyhow::{Context, anyhow, bail};
use data::{DEFAULT_UNIFORM_TOLERANCE, NumericStream, NumericTable, StreamedTimeAxis};
use sindy::Derivative;
use sindy::{
    FeatureLibrary, FitShape, LibrarySpec, Mat, OptimizerSpec, RowBlock, RowSource, Score,
    SindyError, SindyModel, SindyParams, Trajectory,
};

use outputs::{Existing, OutputSet};

use super::Global;

#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum OptimizerKind {
    /// Sequentially thresholded least squares (PySINDy's STLSQ).
    Stlsq,
    /// min ½‖Θξ − ẋ‖² + λ‖ξ‖₁, solved with clarabel.
    Lasso,
}

#[derive(clap::Args, Debug)]
pub struct Args {
    /// A numeric CSV file with a header row.
    #[arg(long)]
    pub csv: PathBuf,
    /// The time column (uniformly sampled, strictly increasing).
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
    /// the file (the default for files over 8 MiB; the file must be a regular file).
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

/// The fit of a file read whole; its model, score on all rows and number of rows.
fn fit_whole(
    args: &Args,
    params: &SindyParams,
    columns: &[&str],
    feature_count: usize,
) -> anyhow::Result<(SindyModel, Score, usize)> {
    let (time, table) = NumericTable::read_with_time(&args.csv, &args.time, columns)?;
    let n = table.rows();
    check_rows(args, n, feature_count, columns)?;
    check_memory(args, n, feature_count, RowSource::Whole)?;
    let dim_x = args.state.len();
    let states = Mat::from_fn(n, dim_x, |i, j| table.columns[j][i]);
    let controls = Mat::from_fn(n, args.control.len(), |i, j| table.columns[dim_x + j][i]);
    let trajectory = Trajectory::new(time, states)?.with_controls(controls)?;
    let model = params
        .fit(std::slice::from_ref(&trajectory))
        .map_err(|error| fit_error(args, error, |row| table.line(row)))?;
    let score = model.score(&trajectory)?;
    Ok((model, score, n))
}

/// The fit of a file read in two passes of blocks: the time column (checked as a uniform axis),
/// then the rows, fitted as they come.
fn fit_streamed(
    args: &Args,
    params: &SindyParams,
    columns: &[&str],
    feature_count: usize,
) -> anyhow::Result<(SindyModel, Score, usize)> {
    let mut stream = NumericStream::open(&args.csv, &[args.time.as_str()])?;
    let mut axis = StreamedTimeAxis::new(&args.csv, &args.time, DEFAULT_UNIFORM_TOLERANCE);
    while let Some(block) = stream.next_block(STREAM_BLOCK_ROWS)? {
        axis.push(&block.columns[0])?;
    }
    let (n, dt) = axis.finish()?;
    check_rows(args, n, feature_count, columns)?;
    check_memory(args, n, feature_count, RowSource::Streamed)?;
    let mut stream = NumericStream::open(&args.csv, columns)?;
    let fit = params
        .fit_streamed(n, dt, || {
            let block = stream
                .next_block(STREAM_BLOCK_ROWS)
                .map_err(|error| SindyError::Source(Box::new(error)))?;
            Ok(block.map(|block| RowBlock {
                columns: block.columns,
            }))
        })
        .map_err(|error| fit_error(args, error, |row| row + 2))?;
    Ok((fit.model, fit.score, n))
}

fn check_rows(args: &Args, n: usize, feature_count: usize, columns: &[&str]) -> anyhow::Result<()> {
    let needed = args.derivative.min_samples();
    if n < needed {
        bail!(
            "{}: {n} data rows, too few: the {} estimator needs at least {needed} (its window)",
            args.csv.display(),
            args.derivative
        );
    }
    if n < feature_count {
        bail!(
            "{}: {n} data rows, fewer than the {feature_count} features of library {} on {}: \
             the fit needs at least one row per feature",
            args.csv.display(),
            args.fit.library,
            columns.join(", ")
        );
    }
    Ok(())
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
            args.csv.display(),
            args.fit.library,
            super::memory::in_words(needed),
            bound.source,
            super::memory::in_words(bound.bytes),
        );
    }
    Ok(())
}

/// A fit's error, a non-finite value named by the line of its row.
fn fit_error(args: &Args, error: SindyError, line: impl Fn(usize) -> usize) -> anyhow::Error {
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
                args.csv.display(),
                line(row),
            )
        }
        other => anyhow::Error::new(other).context(format!("fitting {}", args.csv.display())),
    }
}

pub fn run(_global: &Global, args: Args) -> anyhow::Result<()> {
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
            set.input("the --csv input", &args.csv);
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
    let streamed = args.stream
        || std::fs::metadata(&args.csv)
            .is_ok_and(|metadata| metadata.is_file() && metadata.len() > STREAM_ABOVE_BYTES);
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
            args.csv.display(),
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
    // R² divides by the variance of the target: on a constant one it is rounding noise, so such
    // states are left out of it and named.
    let states = model.state_names();
    let constant: Vec<String> = score
        .constant_states
        .iter()
        .map(|&j| format!("{}'", states[j]))
        .collect();
    let r2 = match score.r2_varying {
        _ if constant.is_empty() => format!("R² {:.6}", score.r2),
        Some(r2) => format!(
            "R² {r2:.6} over the {} of {} states whose target varies ({} constant: no R²)",
            states.len() - constant.len(),
            states.len(),
            constant.join(", ")
        ),
        None => "R² n/a (constant target)".to_string(),
    };
    note!(
        "{} samples, {} features; MSE {:.6}, {r2}",
        n,
        model.feature_names().len(),
        score.mse,
    );
    if let Some(out) = &args.out {
        note!("model written to {}", out.display());
    }
    Ok(())
}
