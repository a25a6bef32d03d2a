//! SINDy models: fit on trajectories with controls, predict, score, print, simulate.

use crate::differentiation::Derivative;
use faer::{Mat, MatRef};

use crate::error::{Result, SindyError, invalid, shape};
use crate::library::{FeatureLibrary, LibrarySpec};
use crate::linalg::product;
use crate::optimizers::RowReduction;
use crate::optimizers::row_blocks::{BLOCK_ROWS, reduce_row_blocks};
use crate::optimizers::{Optimizer, OptimizerSpec, Problem};

/// One recorded trajectory: states x(t), optional controls u(t), optional derivatives ẋ(t).
/// Derivatives estimated from the states use the true time stamps
/// ([`Derivative::apply_at_times`]): the samples need not be evenly spaced, except for
/// Savitzky–Golay.
#[derive(Clone, Debug)]
pub struct Trajectory {
    /// Time of each sample, s, strictly increasing.
    pub time: Vec<f64>,
    /// One row per sample, one column per state.
    pub states: Mat<f64>,
    /// One row per sample, one column per control (zero columns: no control).
    pub controls: Mat<f64>,
    /// ẋ, one row per sample; `None`: estimated with the model's [`Derivative`].
    pub derivatives: Option<Mat<f64>>,
}

impl Trajectory {
    /// A trajectory without controls; checks that `time` matches the rows and increases.
    pub fn new(time: Vec<f64>, states: Mat<f64>) -> Result<Self> {
        if time.len() != states.nrows() {
            return Err(shape(
                "trajectory",
                format!("{} times for {} state rows", time.len(), states.nrows()),
            ));
        }
        if let Some(k) = time.windows(2).position(|w| !increasing(w[0], w[1])) {
            return Err(shape(
                "trajectory",
                format!("time is not strictly increasing at sample {}", k + 1),
            ));
        }
        let controls = Mat::zeros(states.nrows(), 0);
        Ok(Self {
            time,
            states,
            controls,
            derivatives: None,
        })
    }

    /// Adds control inputs, one row per sample.
    pub fn with_controls(mut self, controls: Mat<f64>) -> Result<Self> {
        if controls.nrows() != self.states.nrows() {
            return Err(shape(
                "trajectory",
                format!(
                    "{} control rows for {} state rows",
                    controls.nrows(),
                    self.states.nrows()
                ),
            ));
        }
        self.controls = controls;
        Ok(self)
    }

    /// Adds known derivatives ẋ, same shape as the states.
    pub fn with_derivatives(mut self, derivatives: Mat<f64>) -> Result<Self> {
        if derivatives.shape() != self.states.shape() {
            return Err(shape(
                "trajectory",
                format!(
                    "derivatives are {:?}, states {:?}",
                    derivatives.shape(),
                    self.states.shape()
                ),
            ));
        }
        self.derivatives = Some(derivatives);
        Ok(self)
    }

    fn len(&self) -> usize {
        self.states.nrows()
    }

    /// X = [x, u], one row per sample.
    fn inputs(&self) -> Mat<f64> {
        concatenate_columns(self.states.as_ref(), self.controls.as_ref())
    }

    /// ẋ: the given derivatives, or the estimate of `derivative` on each state column at the
    /// trajectory's time stamps.
    fn targets(&self, derivative: Derivative) -> Result<Mat<f64>> {
        if let Some(d) = &self.derivatives {
            return Ok(d.clone());
        }
        if self.len() < 2 {
            return Err(shape("trajectory", "needs at least two samples"));
        }
        Ok(derivative.apply_columns_at_times(self.states.as_ref(), &self.time)?)
    }
}

/// Goodness of fit of ẋ on a trajectory.
#[derive(Clone, Debug, PartialEq)]
pub struct Score {
    /// Mean over samples and state dimensions of the squared error.
    pub mse: f64,
    /// Coefficient of determination averaged uniformly over state dimensions (scikit-learn's
    /// `r2_score`, PySINDy's default score). Meaningless when `constant_states` is not empty.
    pub r2: f64,
    /// The states (indices) whose target is constant up to rounding (a spread of at most 1e-9 of
    /// its largest magnitude): their R² would divide by rounding noise.
    pub constant_states: Vec<usize>,
    /// R² averaged over the other states only; `None` when every target is constant.
    pub r2_varying: Option<f64>,
}

impl Score {
    /// Whether [`Score::r2`] means anything: no state has a constant target.
    pub fn r2_defined(&self) -> bool {
        self.constant_states.is_empty()
    }
}

/// Entries (rows × features) above which a library is evaluated by blocks of rows and the fit
/// reduced as it is built (see [`Problem::reduced`]) instead of forming Θ whole: 2²² entries,
/// 32 MB.
pub const LARGE_LIBRARY_ENTRIES: usize = 1 << 22;

/// Settings of a SINDy fit, checked when [`SindyParams::fit`] runs.
#[derive(Clone, Debug)]
pub struct SindyParams {
    state_names: Vec<String>,
    control_names: Vec<String>,
    library: FeatureLibrary,
    library_spec: Option<LibrarySpec>,
    optimizer: OptimizerSpec,
    derivative: Derivative,
    pub(crate) reduction: RowReduction,
}

impl SindyParams {
    /// Defaults as in PySINDy: polynomial library of degree 2 with constant, STLSQ threshold 0.1
    /// (alpha 0.05, 20 iterations); derivatives by central differences.
    pub fn new(state_names: &[&str], control_names: &[&str]) -> Self {
        let spec = LibrarySpec::Polynomial {
            degree: 2,
            constant: true,
        };
        Self {
            state_names: state_names.iter().map(|s| s.to_string()).collect(),
            control_names: control_names.iter().map(|s| s.to_string()).collect(),
            library: FeatureLibrary::from_spec(&spec).expect("a valid built-in library"),
            library_spec: Some(spec),
            optimizer: OptimizerSpec::stlsq(0.1),
            derivative: Derivative::Central,
            reduction: RowReduction::default(),
        }
    }

    /// Uses `library` (polynomial, Fourier, custom or concatenated).
    pub fn library(mut self, library: FeatureLibrary) -> Self {
        self.library_spec = library.spec();
        self.library = library;
        self
    }

    /// Uses `optimizer`.
    pub fn optimizer(mut self, optimizer: OptimizerSpec) -> Self {
        self.optimizer = optimizer;
        self
    }

    /// Estimates missing derivatives with `derivative`.
    pub fn derivative(mut self, derivative: Derivative) -> Self {
        self.derivative = derivative;
        self
    }

    /// Reduces the rows of fits too long to hold whole by `reduction` (the guarded Gram matrix by
    /// default).
    pub fn reduction(mut self, reduction: RowReduction) -> Self {
        self.reduction = reduction;
        self
    }

    /// Fits one model on all `trajectories` (their samples stacked).
    pub fn fit(&self, trajectories: &[Trajectory]) -> Result<SindyModel> {
        self.check_names()?;
        if trajectories.is_empty() {
            return Err(invalid("trajectories", "at least one is needed"));
        }
        let (dim_x, dim_u) = (self.state_names.len(), self.control_names.len());
        let mut inputs = Vec::with_capacity(trajectories.len());
        let mut targets = Vec::with_capacity(trajectories.len());
        for (index, trajectory) in trajectories.iter().enumerate() {
            if trajectory.states.ncols() != dim_x || trajectory.controls.ncols() != dim_u {
                return Err(shape(
                    &format!("trajectory {index}"),
                    format!(
                        "{} states and {} controls, the model names {dim_x} and {dim_u}",
                        trajectory.states.ncols(),
                        trajectory.controls.ncols()
                    ),
                ));
            }
            inputs.push(trajectory.inputs());
            targets.push(trajectory.targets(self.derivative)?);
        }
        let inputs = stack_rows(&inputs);
        let targets = stack_rows(&targets);
        self.fit_matrices(inputs.as_ref(), targets.as_ref())
    }

    /// Fits on inputs X = [x, u] and targets ẋ given as matrices (one row per sample).
    ///
    /// A library of more than [`LARGE_LIBRARY_ENTRIES`] entries is never formed whole: it is
    /// evaluated and reduced by blocks of rows (see [`Problem::reduced`]), in memory independent
    /// of the number of rows, with the same coefficients up to rounding.
    ///
    /// ```
    /// use sindy::{Mat, SindyParams};
    /// // ẋ = u − x at scattered points (x, u), the derivatives known
    /// let inputs = Mat::from_fn(100, 2, |i, j| ((i * (j + 3)) as f64 * 0.77).sin());
    /// let targets = Mat::from_fn(100, 1, |i, _| inputs[(i, 1)] - inputs[(i, 0)]);
    /// let model = SindyParams::new(&["x"], &["u"]).fit_matrices(inputs.as_ref(), targets.as_ref())?;
    /// assert_eq!(model.equations(2), vec!["x' = -1.00 x + 1.00 u"]);
    /// let predicted = model.predict_inputs(inputs.as_ref())?;
    /// assert!((predicted[(7, 0)] - targets[(7, 0)]).abs() < 1e-12);
    /// # Ok::<(), sindy::SindyError>(())
    /// ```
    pub fn fit_matrices(
        &self,
        inputs: MatRef<'_, f64>,
        targets: MatRef<'_, f64>,
    ) -> Result<SindyModel> {
        let features = self.library.feature_count(inputs.ncols());
        if inputs.nrows().saturating_mul(features) <= LARGE_LIBRARY_ENTRIES {
            return Ok(self.fit_with_library_matrix(inputs, targets)?.0);
        }
        let optimizer = self.check_fit_inputs(inputs, targets)?;
        let names = self.input_names();
        let input_names: Vec<&str> = names.iter().map(String::as_str).collect();
        let feature_names = self.library.feature_names(&input_names);
        let sizes = FeatureSizes::new(features);
        let shape = (inputs.nrows(), features, targets.ncols());
        let block = |rows: std::ops::Range<usize>, theta: &mut Mat<f64>| {
            let inputs = inputs.subrows(rows.start, rows.len());
            self.library_block(inputs, rows.start, &feature_names, &sizes, theta)?;
            Ok::<_, SindyError>(targets.subrows(rows.start, rows.len()).to_owned())
        };
        let solve = |reduced: Problem<'static>| {
            check_scale(&sizes.to_vec(), &feature_names)?;
            let reduced = reduced.with_target_names(&self.state_names);
            let coefficients = optimizer.solve(&reduced)?;
            Ok((reduced, coefficients))
        };
        let ((_, coefficients), _) = reduce_row_blocks(self.reduction, shape, block, solve)?;
        Ok(self.model(feature_names, coefficients))
    }

    /// The library on a block of rows whose first is row `first_row` of the fit: checked finite
    /// (an error names the row of the fit), its features' sizes recorded in `sizes`.
    pub(crate) fn library_block(
        &self,
        inputs: MatRef<'_, f64>,
        first_row: usize,
        feature_names: &[String],
        sizes: &FeatureSizes,
        theta: &mut Mat<f64>,
    ) -> Result<()> {
        self.library.transform_into(inputs, theta);
        check_finite("library", theta.as_ref(), &|j| {
            format!("feature '{}'", feature_names[j])
        })
        .map_err(|error| error.offset_row(first_row))?;
        sizes.record(theta.as_ref());
        Ok(())
    }

    /// [`Self::fit_matrices`], also returning Θ(X) of the inputs (to predict on them for free).
    pub(crate) fn fit_with_library_matrix(
        &self,
        inputs: MatRef<'_, f64>,
        targets: MatRef<'_, f64>,
    ) -> Result<(SindyModel, Mat<f64>)> {
        let optimizer = self.check_fit_inputs(inputs, targets)?;
        let names = self.input_names();
        let input_names: Vec<&str> = names.iter().map(String::as_str).collect();
        let feature_names = self.library.feature_names(&input_names);
        let theta = self.library.transform(inputs);
        check_finite("library", theta.as_ref(), &|j| {
            format!("feature '{}'", feature_names[j])
        })?;
        check_scale(&column_sizes(theta.as_ref()), &feature_names)?;
        let problem = Problem::new(theta.as_ref(), targets).with_target_names(&self.state_names);
        let coefficients = optimizer.solve(&problem)?;
        Ok((self.model(feature_names, coefficients), theta))
    }

    /// Fits on inputs X = [x, u] and targets ẋ, and returns the model with its prediction of ẋ on
    /// the same inputs (Θ(X)·Ξᵀ, from the library matrix the fit built: no second evaluation).
    pub fn fit_and_predict(
        &self,
        inputs: MatRef<'_, f64>,
        targets: MatRef<'_, f64>,
    ) -> Result<(SindyModel, Mat<f64>)> {
        let (model, theta) = self.fit_with_library_matrix(inputs, targets)?;
        let prediction = product(theta.as_ref(), model.coefficients().transpose());
        Ok((model, prediction))
    }

    pub(crate) fn model(&self, feature_names: Vec<String>, coefficients: Mat<f64>) -> SindyModel {
        SindyModel {
            feature_names,
            state_names: self.state_names.clone(),
            control_names: self.control_names.clone(),
            library: self.library.clone(),
            library_spec: self.library_spec.clone(),
            optimizer: self.optimizer,
            derivative: self.derivative,
            coefficients,
        }
    }

    /// The checked optimizer, once the names, shapes and values of a fit's inputs are checked.
    fn check_fit_inputs(
        &self,
        inputs: MatRef<'_, f64>,
        targets: MatRef<'_, f64>,
    ) -> Result<Box<dyn Optimizer>> {
        self.check_names()?;
        let optimizer = self.optimizer.checked()?;
        let (dim_x, dim_u) = (self.state_names.len(), self.control_names.len());
        if inputs.ncols() != dim_x + dim_u || targets.ncols() != dim_x {
            return Err(shape(
                "fit",
                format!(
                    "inputs have {} columns and targets {}, expected {} and {dim_x}",
                    inputs.ncols(),
                    targets.ncols(),
                    dim_x + dim_u
                ),
            ));
        }
        if inputs.nrows() != targets.nrows() || inputs.nrows() == 0 {
            return Err(shape(
                "fit",
                format!(
                    "{} input rows, {} target rows",
                    inputs.nrows(),
                    targets.nrows()
                ),
            ));
        }
        let names = self.input_names();
        check_finite("inputs", inputs, &|j| format!("input '{}'", names[j]))?;
        check_finite("targets", targets, &|j| {
            format!("target {}'", self.state_names[j])
        })?;
        Ok(optimizer)
    }

    pub(crate) fn state_names(&self) -> &[String] {
        &self.state_names
    }

    pub(crate) fn control_names(&self) -> &[String] {
        &self.control_names
    }

    pub(crate) fn derivative_estimator(&self) -> Derivative {
        self.derivative
    }

    pub(crate) fn library_feature_count(&self, inputs: usize) -> usize {
        self.library.feature_count(inputs)
    }

    /// The names are checked and the optimizer with them.
    pub(crate) fn checked_optimizer(&self) -> Result<Box<dyn Optimizer>> {
        self.check_names()?;
        self.optimizer.checked()
    }

    /// The library's feature names on the inputs [x, u].
    pub(crate) fn feature_names_for_inputs(&self) -> Vec<String> {
        let names = self.input_names();
        let input_names: Vec<&str> = names.iter().map(String::as_str).collect();
        self.library.feature_names(&input_names)
    }

    /// Inputs and targets are finite (errors name the row within them).
    pub(crate) fn check_values(
        &self,
        inputs: MatRef<'_, f64>,
        targets: MatRef<'_, f64>,
    ) -> Result<()> {
        let names = self.input_names();
        check_finite("inputs", inputs, &|j| format!("input '{}'", names[j]))?;
        check_finite("targets", targets, &|j| {
            format!("target {}'", self.state_names[j])
        })
    }

    fn input_names(&self) -> Vec<String> {
        self.state_names
            .iter()
            .chain(&self.control_names)
            .cloned()
            .collect()
    }

    fn check_names(&self) -> Result<()> {
        if self.state_names.is_empty() {
            return Err(invalid("state names", "at least one state is needed"));
        }
        let names = self.input_names();
        for (i, name) in names.iter().enumerate() {
            if name.is_empty() || names[..i].contains(name) {
                return Err(invalid(
                    "variable names",
                    format!("'{name}' is empty or given twice"),
                ));
            }
        }
        let inputs: Vec<&str> = names.iter().map(String::as_str).collect();
        self.library.unique_feature_names(&inputs)?;
        Ok(())
    }
}

/// A fitted SINDy model ẋ = ξ·Θ(x, u).
#[derive(Clone, Debug)]
pub struct SindyModel {
    pub(crate) state_names: Vec<String>,
    pub(crate) control_names: Vec<String>,
    pub(crate) feature_names: Vec<String>,
    pub(crate) library: FeatureLibrary,
    pub(crate) library_spec: Option<LibrarySpec>,
    pub(crate) optimizer: OptimizerSpec,
    pub(crate) derivative: Derivative,
    /// One row per state, one column per feature.
    pub(crate) coefficients: Mat<f64>,
}

impl SindyModel {
    /// Names of the states, in column order.
    pub fn state_names(&self) -> &[String] {
        &self.state_names
    }

    /// Names of the controls, in column order.
    pub fn control_names(&self) -> &[String] {
        &self.control_names
    }

    /// Names of the library's features, in column order.
    pub fn feature_names(&self) -> &[String] {
        &self.feature_names
    }

    /// ξ: one row per state, one column per feature (PySINDy's `coefficients()`).
    pub fn coefficients(&self) -> MatRef<'_, f64> {
        self.coefficients.as_ref()
    }

    /// The coefficient of `feature` in the equation of `state`, if both exist.
    pub fn coefficient(&self, state: &str, feature: &str) -> Option<f64> {
        let i = self.state_names.iter().position(|s| s == state)?;
        let j = self.feature_names.iter().position(|f| f == feature)?;
        Some(self.coefficients[(i, j)])
    }

    /// The optimizer the model was fitted with.
    pub fn optimizer(&self) -> OptimizerSpec {
        self.optimizer
    }

    /// The derivative estimator used for trajectories without derivatives.
    pub fn derivative(&self) -> Derivative {
        self.derivative
    }

    /// The library's specification (`None` for custom functions).
    pub fn library_spec(&self) -> Option<&LibrarySpec> {
        self.library_spec.as_ref()
    }

    /// Predicted ẋ for inputs X = [x, u] (one row per sample).
    pub fn predict_inputs(&self, inputs: MatRef<'_, f64>) -> Result<Mat<f64>> {
        let expected = self.state_names.len() + self.control_names.len();
        if inputs.ncols() != expected {
            return Err(shape(
                "predict",
                format!("{} input columns, the model has {expected}", inputs.ncols()),
            ));
        }
        let features = self.coefficients.ncols();
        if inputs.nrows().saturating_mul(features) <= LARGE_LIBRARY_ENTRIES {
            let theta = self.library.transform(inputs);
            return Ok(product(theta.as_ref(), self.coefficients.transpose()));
        }
        // A large library is evaluated by blocks of rows, never whole.
        let mut prediction = Mat::zeros(inputs.nrows(), self.coefficients.nrows());
        for start in (0..inputs.nrows()).step_by(BLOCK_ROWS) {
            let rows = BLOCK_ROWS.min(inputs.nrows() - start);
            let theta = self.library.transform(inputs.subrows(start, rows));
            prediction
                .as_mut()
                .subrows_mut(start, rows)
                .copy_from(product(theta.as_ref(), self.coefficients.transpose()));
        }
        Ok(prediction)
    }

    /// Predicted ẋ for states x and controls u (one row per sample; u may have zero columns when
    /// the model has no control).
    pub fn predict(&self, states: MatRef<'_, f64>, controls: MatRef<'_, f64>) -> Result<Mat<f64>> {
        if states.nrows() != controls.nrows() {
            return Err(shape(
                "predict",
                format!(
                    "{} state rows, {} control rows",
                    states.nrows(),
                    controls.nrows()
                ),
            ));
        }
        self.predict_inputs(concatenate_columns(states, controls).as_ref())
    }

    /// MSE and R² of the predicted ẋ against the trajectory's derivatives (estimated with the
    /// model's derivative estimator when the trajectory has none).
    pub fn score(&self, trajectory: &Trajectory) -> Result<Score> {
        self.score_all(std::slice::from_ref(trajectory))
    }

    /// [`SindyModel::score`] over several trajectories, their samples stacked (PySINDy's score
    /// with multiple trajectories); each trajectory's derivatives are estimated on its own.
    pub fn score_all(&self, trajectories: &[Trajectory]) -> Result<Score> {
        if trajectories.is_empty() {
            return Err(invalid("trajectories", "at least one is needed"));
        }
        let mut predicted = Vec::with_capacity(trajectories.len());
        let mut actual = Vec::with_capacity(trajectories.len());
        for trajectory in trajectories {
            predicted.push(self.predict(trajectory.states.as_ref(), trajectory.controls.as_ref())?);
            actual.push(trajectory.targets(self.derivative)?);
        }
        let (predicted, actual) = (stack_rows(&predicted), stack_rows(&actual));
        let constant_states = constant_columns(actual.as_ref());
        let varying: Vec<usize> = (0..actual.ncols())
            .filter(|j| !constant_states.contains(j))
            .collect();
        let columns =
            |m: &Mat<f64>| Mat::from_fn(m.nrows(), varying.len(), |i, k| m[(i, varying[k])]);
        let r2_varying = (!varying.is_empty())
            .then(|| r2_score(columns(&predicted).as_ref(), columns(&actual).as_ref()));
        Ok(Score {
            mse: mean_squared_error(predicted.as_ref(), actual.as_ref()),
            r2: r2_score(predicted.as_ref(), actual.as_ref()),
            constant_states,
            r2_varying,
        })
    }

    /// One line per state: `x' = 1.000 y - 0.100 x` with `precision` decimals; the constant
    /// feature is printed as a bare number; a state without terms reads `x' = 0`.
    pub fn equations(&self, precision: usize) -> Vec<String> {
        self.state_names
            .iter()
            .enumerate()
            .map(|(i, state)| {
                let mut line = format!("{state}' =");
                let mut first = true;
                for (j, feature) in self.feature_names.iter().enumerate() {
                    let c = self.coefficients[(i, j)];
                    if c == 0.0 {
                        continue;
                    }
                    let magnitude = format!("{:.precision$}", c.abs());
                    let sign = match (first, c < 0.0) {
                        (true, false) => " ".to_string(),
                        (true, true) => " -".to_string(),
                        (false, false) => " + ".to_string(),
                        (false, true) => " - ".to_string(),
                    };
                    line.push_str(&sign);
                    line.push_str(&magnitude);
                    if feature != "1" {
                        line.push(' ');
                        line.push_str(feature);
                    }
                    first = false;
                }
                if first {
                    line.push_str(" 0");
                }
                line
            })
            .collect()
    }

    /// The right-hand side f(x, u) at one point.
    fn rhs(
        &self,
        state: &[f64],
        control: &[f64],
        row: &mut Vec<f64>,
        input: &mut Vec<f64>,
    ) -> Vec<f64> {
        input.clear();
        input.extend_from_slice(state);
        input.extend_from_slice(control);
        self.library.transform_row(input, row);
        (0..self.state_names.len())
            .map(|i| {
                (0..row.len())
                    .map(|j| self.coefficients[(i, j)] * row[j])
                    .sum()
            })
            .collect()
    }

    /// Integrates ẋ = f(x, u) from `x0` over the sample times `time` with classic RK4, one step
    /// per interval. The controls (one row per time, or zero columns without control) are
    /// interpolated linearly between samples, so the mid-step control is the mean of the two
    /// neighbouring samples. Returns the states at every time (first row = `x0`).
    ///
    /// ```
    /// use sindy::{Mat, SindyParams};
    /// // ẋ = −x, fitted from exact derivatives, then integrated from x = 1 for one second
    /// let inputs = Mat::from_fn(50, 1, |i, _| i as f64 * 0.1 - 2.5);
    /// let targets = Mat::from_fn(50, 1, |i, _| -inputs[(i, 0)]);
    /// let model = SindyParams::new(&["x"], &[]).fit_matrices(inputs.as_ref(), targets.as_ref())?;
    /// let time: Vec<f64> = (0..=100).map(|k| k as f64 * 0.01).collect();
    /// let states = model.simulate(&[1.0], &time, Mat::<f64>::zeros(101, 0).as_ref())?;
    /// assert!((states[(100, 0)] - (-1.0f64).exp()).abs() < 1e-9);
    /// # Ok::<(), sindy::SindyError>(())
    /// ```
    pub fn simulate(
        &self,
        x0: &[f64],
        time: &[f64],
        controls: MatRef<'_, f64>,
    ) -> Result<Mat<f64>> {
        let dim_x = self.state_names.len();
        if x0.len() != dim_x {
            return Err(shape(
                "simulate",
                format!("x0 has {} values, the model {dim_x} states", x0.len()),
            ));
        }
        if controls.ncols() != self.control_names.len() || controls.nrows() != time.len() {
            return Err(shape(
                "simulate",
                format!(
                    "controls are {}x{}, expected {}x{}",
                    controls.nrows(),
                    controls.ncols(),
                    time.len(),
                    self.control_names.len()
                ),
            ));
        }
        if time.is_empty() || time.windows(2).any(|w| !increasing(w[0], w[1])) {
            return Err(shape(
                "simulate",
                "time must be non-empty and strictly increasing",
            ));
        }
        let mut states = Mat::zeros(time.len(), dim_x);
        let mut x = x0.to_vec();
        let (mut row, mut input) = (Vec::new(), Vec::new());
        let control_at =
            |k: usize| -> Vec<f64> { (0..controls.ncols()).map(|j| controls[(k, j)]).collect() };
        for j in 0..dim_x {
            states[(0, j)] = x[j];
        }
        for k in 0..time.len() - 1 {
            let h = time[k + 1] - time[k];
            let (u0, u1) = (control_at(k), control_at(k + 1));
            let middle: Vec<f64> = u0.iter().zip(&u1).map(|(a, b)| 0.5 * (a + b)).collect();
            let step = |x: &[f64], d: &[f64], scale: f64| -> Vec<f64> {
                x.iter().zip(d).map(|(a, b)| a + scale * b).collect()
            };
            let k1 = self.rhs(&x, &u0, &mut row, &mut input);
            let k2 = self.rhs(&step(&x, &k1, h / 2.0), &middle, &mut row, &mut input);
            let k3 = self.rhs(&step(&x, &k2, h / 2.0), &middle, &mut row, &mut input);
            let k4 = self.rhs(&step(&x, &k3, h), &u1, &mut row, &mut input);
            for j in 0..dim_x {
                x[j] += h / 6.0 * (k1[j] + 2.0 * k2[j] + 2.0 * k3[j] + k4[j]);
                states[(k + 1, j)] = x[j];
            }
            if x.iter().any(|v| !v.is_finite()) {
                return Err(SindyError::Solver {
                    solver: "RK4 simulation",
                    target: self.state_names.join(","),
                    message: format!("the state diverged at t = {}", time[k + 1]),
                });
            }
        }
        Ok(states)
    }
}

/// Mean over all samples and all columns of the squared difference.
pub fn mean_squared_error(predicted: MatRef<'_, f64>, actual: MatRef<'_, f64>) -> f64 {
    let (n, m) = actual.shape();
    let sum: f64 = (0..m)
        .map(|j| {
            predicted
                .col(j)
                .iter()
                .zip(actual.col(j).iter())
                .map(|(p, a)| (p - a) * (p - a))
                .sum::<f64>()
        })
        .sum();
    sum / (n * m) as f64
}

/// The columns of `actual` that are constant up to rounding: standard deviation at most
/// [`CONSTANT_RELATIVE_SPREAD`] times the largest magnitude in the column (all zeros included).
/// R² is undefined on them.
pub(crate) fn constant_columns(actual: MatRef<'_, f64>) -> Vec<usize> {
    let n = actual.nrows();
    (0..actual.ncols())
        .filter(|&j| {
            let column = || (0..n).map(|i| actual[(i, j)]);
            let mean = column().sum::<f64>() / n as f64;
            let variance = column().map(|v| (v - mean).powi(2)).sum::<f64>() / n as f64;
            let scale = column().fold(0.0_f64, |m, v| m.max(v.abs()));
            n == 0 || variance.sqrt() <= CONSTANT_RELATIVE_SPREAD * scale
        })
        .collect()
}

/// See [`constant_columns`]: a spread this small relative to the values is rounding noise (a
/// derivative estimate of x = 2t varies by ~1e-15).
pub(crate) const CONSTANT_RELATIVE_SPREAD: f64 = 1e-9;

/// Coefficient of determination, averaged uniformly over columns (scikit-learn's `r2_score`).
pub(crate) fn r2_score(predicted: MatRef<'_, f64>, actual: MatRef<'_, f64>) -> f64 {
    let (n, m) = actual.shape();
    let mut total = 0.0;
    for j in 0..m {
        let mean = (0..n).map(|i| actual[(i, j)]).sum::<f64>() / n as f64;
        let residual: f64 = (0..n)
            .map(|i| (actual[(i, j)] - predicted[(i, j)]).powi(2))
            .sum();
        let spread: f64 = (0..n).map(|i| (actual[(i, j)] - mean).powi(2)).sum();
        total += match (spread > 0.0, residual > 0.0) {
            (true, _) => 1.0 - residual / spread,
            (false, false) => 1.0,
            (false, true) => 0.0,
        };
    }
    total / m as f64
}

fn concatenate_columns(left: MatRef<'_, f64>, right: MatRef<'_, f64>) -> Mat<f64> {
    let split = left.ncols();
    Mat::from_fn(left.nrows(), split + right.ncols(), |i, j| {
        if j < split {
            left[(i, j)]
        } else {
            right[(i, j - split)]
        }
    })
}

fn stack_rows(blocks: &[Mat<f64>]) -> Mat<f64> {
    let rows = blocks.iter().map(Mat::nrows).sum();
    let cols = blocks.first().map_or(0, Mat::ncols);
    let mut out = Mat::zeros(rows, cols);
    let mut offset = 0;
    for block in blocks {
        out.as_mut()
            .submatrix_mut(offset, 0, block.nrows(), cols)
            .copy_from(block);
        offset += block.nrows();
    }
    out
}

pub(crate) fn check_finite(
    what: &str,
    matrix: MatRef<'_, f64>,
    name: &dyn Fn(usize) -> String,
) -> Result<()> {
    for j in 0..matrix.ncols() {
        let column = matrix.col(j);
        // The common case first: a contiguous column checked in one vectorised pass.
        if let Some(slice) = column.try_as_col_major()
            && slice.as_slice().iter().all(|v| v.is_finite())
        {
            continue;
        }
        if let Some(i) = column.iter().position(|v| !v.is_finite()) {
            return Err(SindyError::NonFinite {
                what: what.to_string(),
                row: i,
                column: name(j),
                value: column[i],
            });
        }
    }
    Ok(())
}

/// The most the largest magnitudes of two features of one fit may differ by: beyond it a
/// least-squares fit in double precision (16 digits) cannot resolve the smaller one.
pub(crate) const MAX_FEATURE_SCALE_RATIO: f64 = 1e12;

/// Refuses a library whose features differ in size by more than [`MAX_FEATURE_SCALE_RATIO`]
/// (largest magnitude of each non-zero column): the fit would be noise or not finite.
pub(crate) fn check_scale(sizes: &[f64], names: &[String]) -> Result<()> {
    let sizes = sizes
        .iter()
        .enumerate()
        .filter_map(|(j, &size)| (size > 0.0).then_some((j, size)));
    let (mut small, mut large) = ((0, f64::INFINITY), (0, 0.0));
    for (j, size) in sizes {
        if size < small.1 {
            small = (j, size);
        }
        if size > large.1 {
            large = (j, size);
        }
    }
    if large.1 > small.1 * MAX_FEATURE_SCALE_RATIO {
        return Err(SindyError::Scale {
            large_feature: names[large.0].clone(),
            large: large.1,
            small_feature: names[small.0].clone(),
            small: small.1,
        });
    }
    Ok(())
}

/// The largest magnitude of each feature over blocks of rows evaluated in any order (a maximum).
pub(crate) struct FeatureSizes(std::sync::Mutex<Vec<f64>>);

impl FeatureSizes {
    pub(crate) fn new(features: usize) -> Self {
        Self(std::sync::Mutex::new(vec![0.0; features]))
    }

    pub(crate) fn record(&self, theta: MatRef<'_, f64>) {
        let block = column_sizes(theta);
        let mut sizes = self
            .0
            .lock()
            .unwrap_or_else(|poisoned| poisoned.into_inner());
        for (size, block) in sizes.iter_mut().zip(block) {
            *size = size.max(block);
        }
    }

    pub(crate) fn into_vec(self) -> Vec<f64> {
        self.0
            .into_inner()
            .unwrap_or_else(|poisoned| poisoned.into_inner())
    }

    /// The sizes recorded so far.
    pub(crate) fn to_vec(&self) -> Vec<f64> {
        self.0
            .lock()
            .unwrap_or_else(|poisoned| poisoned.into_inner())
            .clone()
    }
}

/// The largest magnitude of each column.
pub(crate) fn column_sizes(theta: MatRef<'_, f64>) -> Vec<f64> {
    (0..theta.ncols())
        .map(|j| theta.col(j).iter().fold(0.0f64, |m, v| m.max(v.abs())))
        .collect()
}

/// Whether `b` is a finite time strictly after `a`.
fn increasing(a: f64, b: f64) -> bool {
    b.is_finite() && a.is_finite() && b > a
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn scores_follow_scikit_learn() {
        let actual = Mat::from_fn(4, 2, |i, j| (i + 2 * j) as f64);
        assert_eq!(r2_score(actual.as_ref(), actual.as_ref()), 1.0);
        // predicting each column's mean gives R² = 0; a constant column predicted exactly counts 1
        let means = Mat::from_fn(4, 2, |_, j| 1.5 + 2.0 * j as f64);
        assert!(r2_score(means.as_ref(), actual.as_ref()).abs() < 1e-15);
        let constant = Mat::from_fn(4, 1, |_, _| 3.0);
        assert_eq!(r2_score(constant.as_ref(), constant.as_ref()), 1.0);
        assert_eq!(mean_squared_error(means.as_ref(), actual.as_ref()), 1.25);
    }

    #[test]
    fn a_target_constant_up_to_rounding_has_no_r2() {
        // 2 plus rounding noise, zeros, and a column that does vary.
        let actual = Mat::from_fn(6, 3, |i, j| match j {
            0 => 2.0 + if i % 2 == 0 { 4e-16 } else { -4e-16 },
            1 => 0.0,
            _ => i as f64 * 1e-3,
        });
        assert_eq!(constant_columns(actual.as_ref()), vec![0, 1]);
        // On x = 2t the fit is exact, and the score says R² is undefined.
        let time: Vec<f64> = (0..50).map(|k| k as f64 * 0.1).collect();
        let states = Mat::from_fn(50, 1, |i, _| 2.0 * time[i]);
        let trajectory = Trajectory::new(time, states).unwrap();
        let model = SindyParams::new(&["x"], &[])
            .fit(std::slice::from_ref(&trajectory))
            .unwrap();
        let score = model.score(&trajectory).unwrap();
        assert!(score.mse < 1e-20, "{score:?}");
        assert!(!score.r2_defined(), "{score:?}");
        assert_eq!((score.constant_states, score.r2_varying), (vec![0], None));
        let varying = Trajectory::new(
            (0..50).map(|k| k as f64 * 0.1).collect(),
            Mat::from_fn(50, 1, |i, _| (i as f64 * 0.1).sin()),
        )
        .unwrap();
        let score = model.score(&varying).unwrap();
        assert!(score.r2_defined());
        assert_eq!(score.r2_varying, Some(score.r2));
    }

    #[test]
    fn r2_over_the_varying_states_leaves_the_constant_one_out() {
        // x = 2t (constant derivative), y = sin t: the fit of ẏ is scored alone.
        let time: Vec<f64> = (0..200).map(|k| k as f64 * 0.01).collect();
        let states = Mat::from_fn(
            200,
            2,
            |i, j| {
                if j == 0 { 2.0 * time[i] } else { time[i].sin() }
            },
        );
        let trajectory = Trajectory::new(time.clone(), states).unwrap();
        let model = SindyParams::new(&["x", "y"], &[])
            .fit(std::slice::from_ref(&trajectory))
            .unwrap();
        let score = model.score(&trajectory).unwrap();
        assert_eq!(score.constant_states, vec![0]);
        let predicted = model
            .predict(trajectory.states.as_ref(), trajectory.controls.as_ref())
            .unwrap();
        let actual = trajectory.targets(model.derivative).unwrap();
        let only_y = |m: &Mat<f64>| Mat::from_fn(m.nrows(), 1, |i, _| m[(i, 1)]);
        let expected = r2_score(only_y(&predicted).as_ref(), only_y(&actual).as_ref());
        assert_eq!(score.r2_varying, Some(expected));
        assert!(expected > 0.9 && expected < 1.0, "{expected}");
    }

    #[test]
    fn trajectories_are_checked() {
        let states = Mat::<f64>::zeros(3, 1);
        assert!(Trajectory::new(vec![0.0, 1.0], states.clone()).is_err());
        assert!(Trajectory::new(vec![0.0, 1.0, 1.0], states.clone()).is_err());
        let ok = Trajectory::new(vec![0.0, 1.0, 2.0], states).unwrap();
        assert!(ok.clone().with_controls(Mat::zeros(2, 1)).is_err());
        assert!(ok.with_derivatives(Mat::zeros(3, 2)).is_err());
    }
}
