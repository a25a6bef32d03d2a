//! Fitting a recording too long to hold whole: its rows arrive in blocks, each state's derivative
//! is estimated with the neighbouring rows its stencil reads, and the library is evaluated and
//! reduced segment by segment (as [`crate::Problem::reduced`]). Memory is a few segments whatever the
//! length; the coefficients are those of [`SindyParams::fit_matrices`] on the whole recording (the
//! same segments, merged in the same order), and the score follows from the reduced problem.
//! Segments are reduced by one worker thread per rayon thread as their rows arrive, and merged in
//! row order whichever finishes first.

use std::sync::Mutex;
use std::sync::mpsc::{Receiver, Sender, channel, sync_channel};

use faer::Mat;

use crate::differentiation::Derivative;

use crate::error::{Result, SindyError, shape};
use crate::model::{CONSTANT_RELATIVE_SPREAD, FeatureSizes, Score, SindyModel, SindyParams};
use crate::optimizers::row_blocks::{RowMerge, SEGMENT_ROWS, reduce_by, segment_part};
use crate::optimizers::{Reduction, RowReduction};

/// Consecutive rows of a recording: one vector per state, then one per control; and their time
/// stamps when the steps are uneven (`None`: every step is the `dt` of the fit).
#[derive(Clone, Debug, Default)]
pub struct RowBlock {
    pub columns: Vec<Vec<f64>>,
    pub time: Option<Vec<f64>>,
}

/// A model fitted on a streamed recording, with its score on all rows and how its rows were
/// reduced.
#[derive(Clone, Debug)]
pub struct StreamedFit {
    pub model: SindyModel,
    pub score: Score,
    pub rows: usize,
    pub reduction: Reduction,
}

/// Rows before and after a sample that its derivative estimate may read (edge formulas included).
fn context(derivative: Derivative) -> (usize, usize) {
    match derivative {
        Derivative::Forward => (1, 1),
        Derivative::Central => (2, 2),
        Derivative::SavitzkyGolay { window, .. } => (window, window),
    }
}

/// Count, mean, sum of squared deviations and largest magnitude of one target column.
#[derive(Clone, Copy, Debug, Default)]
struct Moments {
    count: f64,
    mean: f64,
    spread: f64,
    largest: f64,
}

impl Moments {
    fn of(values: &[f64]) -> Self {
        let count = values.len() as f64;
        let mean = values.iter().sum::<f64>() / count.max(1.0);
        let spread = values.iter().map(|v| (v - mean).powi(2)).sum();
        let largest = values.iter().fold(0.0, |m: f64, v| m.max(v.abs()));
        Self {
            count,
            mean,
            spread,
            largest,
        }
    }

    /// Chan, Golub and LeVeque's pairwise update.
    fn merge(self, other: Self) -> Self {
        let count = self.count + other.count;
        if count == 0.0 {
            return self;
        }
        let delta = other.mean - self.mean;
        Self {
            count,
            mean: self.mean + delta * other.count / count,
            spread: self.spread + other.spread + delta * delta * self.count * other.count / count,
            largest: self.largest.max(other.largest),
        }
    }
}

/// One segment ready to reduce: inputs [x, u] and targets ẋ, from global row `start`.
struct Segment {
    start: usize,
    inputs: Mat<f64>,
    targets: Mat<f64>,
}

/// The times of the buffered rows: every `dt` seconds, or stamped (one time per row).
#[derive(Clone, Copy)]
enum Sampling<'a> {
    Every(f64),
    Stamped(&'a [f64]),
}

/// What a reduced segment hands to the merge: its part (Gram matrix or triangle), target moments,
/// feature sizes and rows.
type Reduced = (Mat<f64>, Vec<Moments>, Vec<f64>, usize);

/// The segments merged so far: their reduction, target moments and feature sizes.
struct Merged {
    merge: RowMerge,
    moments: Vec<Moments>,
    sizes: Vec<f64>,
}

impl Merged {
    fn add(&mut self, (part, moments, sizes, count): Reduced) {
        self.merge.add(&part, count);
        for (total, part) in self.moments.iter_mut().zip(moments) {
            *total = total.merge(part);
        }
        for (total, part) in self.sizes.iter_mut().zip(sizes) {
            *total = total.max(part);
        }
    }
}

/// Reduced segments that came back before the ones ahead of them, held until those are merged.
#[derive(Default)]
struct InOrder {
    waiting: std::collections::BTreeMap<usize, Result<Reduced>>,
    sent: usize,
    merged: usize,
}

impl InOrder {
    /// Takes segment `index`'s result and merges every result now in order; the first error in
    /// row order stops the fit.
    fn merge(
        &mut self,
        (index, result): (usize, Result<Reduced>),
        into: &mut Merged,
    ) -> Result<()> {
        self.waiting.insert(index, result);
        while let Some(result) = self.waiting.remove(&self.merged) {
            into.add(result?);
            self.merged += 1;
        }
        Ok(())
    }
}

/// The rows read and not yet dropped: every column, and the time stamps when the blocks carry them.
struct RowBuffer {
    columns: Vec<Vec<f64>>,
    times: Option<Vec<f64>>,
    /// The global row of the first buffered row.
    start: usize,
    /// Rows read so far.
    read: usize,
}

impl RowBuffer {
    fn new(width: usize) -> Self {
        Self {
            columns: vec![Vec::new(); width],
            times: None,
            start: 0,
            read: 0,
        }
    }

    /// Reads blocks from `next` until `needed` rows of the recording's `rows` are read.
    fn fill(
        &mut self,
        needed: usize,
        rows: usize,
        next: &mut impl FnMut() -> Result<Option<RowBlock>>,
    ) -> Result<()> {
        while self.read < needed {
            let block = next()?.ok_or_else(|| {
                let read = self.read;
                shape(
                    "recording",
                    format!("ended after {read} rows, {rows} were counted"),
                )
            })?;
            let mixed = self.read > 0 && block.time.is_some() != self.times.is_some();
            check_block(&block, self.columns.len(), mixed)?;
            self.read += block.columns[0].len();
            if let Some(time) = block.time {
                self.times.get_or_insert_with(Vec::new).extend(time);
            }
            for (column, values) in self.columns.iter_mut().zip(block.columns) {
                column.extend(values);
            }
        }
        Ok(())
    }

    /// The times of the buffered rows.
    fn sampling(&self, dt: f64) -> Sampling<'_> {
        match &self.times {
            Some(times) => Sampling::Stamped(times),
            None => Sampling::Every(dt),
        }
    }

    /// Drops the rows before global row `row` (none before the buffer's first).
    fn keep_from(&mut self, row: usize) {
        let row = row.max(self.start);
        for column in self.columns.iter_mut().chain(self.times.as_mut()) {
            column.drain(..row - self.start);
        }
        self.start = row;
    }
}

/// Refuses a block with the wrong number of columns, or with time stamps where the blocks before
/// had none (or the reverse: `mixed`).
fn check_block(block: &RowBlock, width: usize, mixed: bool) -> Result<()> {
    if block.columns.len() != width {
        return Err(shape(
            "recording",
            format!(
                "a block of {} columns, {width} expected",
                block.columns.len()
            ),
        ));
    }
    if mixed {
        return Err(shape("recording", "time stamps in some blocks only"));
    }
    Ok(())
}

impl SindyParams {
    /// Fits on a recording of `rows` rows sampled every `dt` seconds, read from its first row by
    /// the blocks each call of `open` yields in order (any block sizes; `None` at the end): once,
    /// or twice when the Gram matrix of the first reading is refused ([`RowReduction`]). Its
    /// derivatives are those of [`crate::Trajectory`] with the same `dt`; blocks that carry their
    /// time stamps (every block or none) have them estimated on those stamps
    /// ([`Derivative::apply_at_times`]). Errors name rows 0-based from the first.
    pub fn fit_streamed<Blocks>(
        &self,
        rows: usize,
        dt: f64,
        mut open: impl FnMut() -> Result<Blocks>,
    ) -> Result<StreamedFit>
    where
        Blocks: FnMut() -> Result<Option<RowBlock>>,
    {
        let derivative = self.derivative_estimator();
        derivative.validate()?;
        if rows < derivative.min_samples().max(2) {
            return Err(shape(
                "recording",
                format!("{rows} rows, too few for the {derivative} derivative"),
            ));
        }
        let optimizer = self.checked_optimizer()?;
        let names = self.feature_names_for_inputs();
        let attempt = |method| {
            let merged = self.reduce_stream(method, rows, dt, open()?)?;
            crate::model::check_scale(&merged.sizes, &names)?;
            Ok::<_, SindyError>((merged.merge, merged.moments))
        };
        let solve = |problem: crate::Problem<'static>| {
            let reduced = problem.with_target_names(self.state_names());
            let coefficients = optimizer.solve(&reduced)?;
            Ok((reduced, coefficients))
        };
        let ((reduced, coefficients), moments, reduction) =
            reduce_by(self.reduction, attempt, solve)?;
        let residuals = reduced.residual_sum_of_squares(coefficients.as_ref());
        let model = self.model(names, coefficients);
        Ok(StreamedFit {
            model,
            score: score(&residuals, &moments, rows),
            rows,
            reduction,
        })
    }

    /// One reading of the recording: every segment reduced by `method` as its rows arrive from
    /// `next`, and merged in row order.
    fn reduce_stream(
        &self,
        method: RowReduction,
        rows: usize,
        dt: f64,
        mut next: impl FnMut() -> Result<Option<RowBlock>>,
    ) -> Result<Merged> {
        let (dim_x, dim_u) = (self.state_names().len(), self.control_names().len());
        let width = dim_x + dim_u;
        let features = self.library_feature_count(width);
        let (left, right) = context(self.derivative_estimator());
        let mut merged = Merged {
            merge: RowMerge::new(method, features, dim_x),
            moments: vec![Moments::default(); dim_x],
            sizes: vec![0.0f64; features],
        };
        // Segments go to the workers as their rows arrive, at most `workers` waiting, and come
        // back in any order: they are merged in row order, so the result does not depend on the
        // thread count or the timing.
        let workers = rayon::current_num_threads().max(1);
        let (jobs, queue) = sync_channel::<(usize, Segment)>(workers);
        let queue = Mutex::new(queue);
        let (done, finished) = channel::<(usize, Result<Reduced>)>();
        std::thread::scope(|scope| -> Result<()> {
            let jobs = jobs;
            for _ in 0..workers {
                let (queue, done) = (&queue, done.clone());
                scope.spawn(move || self.reduce_segments(method, queue, done, features));
            }
            drop(done);
            let mut order = InOrder::default();
            let mut buffer = RowBuffer::new(width);
            for (index, start) in (0..rows).step_by(SEGMENT_ROWS).enumerate() {
                let end = (start + SEGMENT_ROWS).min(rows);
                let needed = (end + right).min(rows);
                buffer.fill(needed, rows, &mut next)?;
                let segment = self.segment(
                    &buffer.columns,
                    buffer.sampling(dt),
                    buffer.start,
                    start..end,
                    needed,
                )?;
                if jobs.send((index, segment)).is_err() {
                    break;
                }
                order.sent += 1;
                // Keep the rows the next segment's left context needs.
                buffer.keep_from(end.saturating_sub(left));
                while let Ok(result) = finished.try_recv() {
                    order.merge(result, &mut merged)?;
                }
            }
            drop(jobs);
            while order.merged < order.sent {
                let result = (finished.recv())
                    .map_err(|_| shape("recording", "a segment's reduction ended early"))?;
                order.merge(result, &mut merged)?;
            }
            Ok(())
        })?;
        Ok(merged)
    }

    /// A worker: reduces the segments it takes from `queue` until it is closed, and sends each
    /// result with its index.
    fn reduce_segments(
        &self,
        method: RowReduction,
        queue: &Mutex<Receiver<(usize, Segment)>>,
        done: Sender<(usize, Result<Reduced>)>,
        features: usize,
    ) {
        loop {
            let job = match queue.lock() {
                Ok(queue) => queue.recv(),
                Err(_) => return,
            };
            let Ok((index, segment)) = job else {
                return;
            };
            let reduced = self.reduce_segment(method, &segment, features);
            if done.send((index, reduced)).is_err() {
                return;
            }
        }
    }

    /// Inputs and targets of the rows `range`, from the buffer (global rows from `buffer_start`)
    /// that holds the rows up to `available`.
    fn segment(
        &self,
        buffer: &[Vec<f64>],
        sampling: Sampling<'_>,
        buffer_start: usize,
        range: std::ops::Range<usize>,
        available: usize,
    ) -> Result<Segment> {
        let dim_x = self.state_names().len();
        let (left, _) = context(self.derivative_estimator());
        let from = range.start.saturating_sub(left).max(buffer_start);
        let local = |global: usize| global - buffer_start;
        let rows = range.len();
        let mut targets = Mat::zeros(rows, dim_x);
        for (j, column) in buffer.iter().take(dim_x).enumerate() {
            let (first, last) = (local(from), local(available));
            let window = &column[first..last];
            let derivative = match sampling {
                Sampling::Every(dt) => self.derivative_estimator().apply(window, dt)?,
                Sampling::Stamped(times) => self
                    .derivative_estimator()
                    .apply_at_times(window, &times[first..last])?,
            };
            for k in 0..rows {
                targets[(k, j)] = derivative[range.start - from + k];
            }
        }
        let inputs = Mat::from_fn(rows, buffer.len(), |k, j| buffer[j][local(range.start + k)]);
        Ok(Segment {
            start: range.start,
            inputs,
            targets,
        })
    }

    /// One segment's part (by `method`), target moments and feature sizes; non-finite values are
    /// errors naming their global row.
    fn reduce_segment(
        &self,
        method: RowReduction,
        segment: &Segment,
        features: usize,
    ) -> Result<Reduced> {
        self.check_values(segment.inputs.as_ref(), segment.targets.as_ref())
            .map_err(|error| error.offset_row(segment.start))?;
        let names = self.feature_names_for_inputs();
        let sizes = FeatureSizes::new(features);
        let rows = segment.inputs.nrows();
        let width = features + segment.targets.ncols();
        let part = segment_part(method, rows, width, |block, theta| {
            let inputs = segment.inputs.subrows(block.start, block.len());
            let first_row = segment.start + block.start;
            self.library_block(inputs, first_row, &names, &sizes, theta)?;
            Ok::<_, SindyError>(segment.targets.subrows(block.start, block.len()).to_owned())
        })?;
        let moments = (0..segment.targets.ncols())
            .map(|j| Moments::of(&segment.targets.col(j).iter().copied().collect::<Vec<_>>()))
            .collect();
        Ok((part, moments, sizes.into_vec(), rows))
    }
}

/// The score from each target's residual sum of squares and moments (as [`SindyModel::score`]).
fn score(residuals: &[f64], moments: &[Moments], rows: usize) -> Score {
    let constant_states: Vec<usize> = (0..moments.len())
        .filter(|&j| {
            let m = moments[j];
            (m.spread / m.count.max(1.0)).sqrt() <= CONSTANT_RELATIVE_SPREAD * m.largest
        })
        .collect();
    let r2_of = |j: usize| match (moments[j].spread > 0.0, residuals[j] > 0.0) {
        (true, _) => 1.0 - residuals[j] / moments[j].spread,
        (false, false) => 1.0,
        (false, true) => 0.0,
    };
    let varying: Vec<usize> = (0..moments.len())
        .filter(|j| !constant_states.contains(j))
        .collect();
    let m = moments.len().max(1) as f64;
    Score {
        mse: residuals.iter().sum::<f64>() / (rows as f64 * m),
        r2: (0..moments.len()).map(r2_of).sum::<f64>() / m,
        r2_varying: (!varying.is_empty())
            .then(|| varying.iter().map(|&j| r2_of(j)).sum::<f64>() / varying.len() as f64),
        constant_states,
    }
}
