//! One runner for every method on every cell and seed.
//!
//! A [`Method`] is evaluated on an [`EvaluationCell`] with a seed: fitted (SINDy, a variant's
//! regression) or adapted (LeARN) on the cell's support segment only, predicting both segments,
//! scored on each ([`Outcome`]). SINDy ([`crate::SindyConfig`]), LeARN ([`Experiment`]) and every
//! variant ([`crate::VariantSpec`]) are peers behind it. The [`Runner`] evaluates its methods on
//! the cells of a work item with the item's seed ([`Runner::run_cells`], in parallel over the
//! cells), the methods of one cell and seed in order (a `select` or `average` variant takes the
//! outcomes of those before it), and tells the caller's [`Progress`] of each cell as it ends; the
//! sweeps enumerate cells × seeds as work items and run them in parallel ([`crate::Sweep::run`],
//! [`Experiment::run_items`]). The LeARN networks a method asks for ([`Trial::model`]) are
//! meta-trained by the runner's [`Train`] for the cell's fold: once per item for the item's own
//! seed (under `paper` one model serves every cell of the item), on first use for any other seed
//! (the members of an ensemble).

use std::collections::BTreeMap;
use std::sync::Arc;

use learn::MetaTrainedModel;
use rayon::prelude::*;
use sindy::{Mat, RegressionFit, SindyModel};

use crate::error::{EvaluationError, Result};
use crate::experiment::{CellResult, Cells, EvaluationCell, Experiment, WorkItem};
use crate::progress::Progress;
use crate::segment::Segment;
use crate::sindy_variant::SegmentPredictions;

/// A method evaluated on an evaluation cell with a seed. It must read the query segment only to
/// predict and score it: nothing it fits or chooses may depend on the query.
pub trait Method: Sync {
    /// The method's name: a column of the tables, a variant of the variants file.
    fn name(&self) -> &str;

    /// Whether [`Method::evaluate`] asks for the LeARN networks ([`Trial::model`]).
    fn needs_meta_training(&self) -> bool {
        false
    }

    /// Fits or adapts on `trial.cell.support`, predicts both segments and scores each.
    fn evaluate(&self, trial: &mut Trial<'_, '_>) -> Result<Outcome>;
}

/// What a method fitted, beyond its predictions.
#[derive(Clone, Debug)]
pub enum Fitted {
    /// Nothing but the predictions (a mean of other methods' predictions, LeARN adapted by a
    /// variant).
    Predictions,
    /// A regression on named features (the library and learned-basis variants).
    Regression {
        features: Vec<String>,
        fit: RegressionFit,
    },
    /// SINDy's model.
    Sindy(SindyModel),
    /// LeARN's cell: the meta-trained model, its adapted parameters, its scores and coverage.
    Learn(Box<CellResult>),
}

/// One method's outcome on one cell and seed.
#[derive(Clone, Debug)]
pub struct Outcome {
    /// Predictions and MSE on both segments (and the band of a bagged variant).
    pub predictions: SegmentPredictions,
    /// What was fitted.
    pub fitted: Fitted,
    /// Everything chosen inside the support segment (per output penalty; `variant` for select).
    pub chosen: BTreeMap<String, report::Choice>,
    /// Mean over outputs of the best support cross-validation MSE (variants that fit a
    /// regression).
    pub support_cv: Option<f64>,
}

impl Outcome {
    /// Predictions of both segments, scored, with nothing chosen and no band.
    pub fn unfitted(
        support_prediction: Mat<f64>,
        query_prediction: Mat<f64>,
        support: &Segment,
        query: &Segment,
    ) -> Self {
        Self {
            predictions: SegmentPredictions::scored(
                support_prediction,
                query_prediction,
                support.targets.as_ref(),
                query.targets.as_ref(),
            ),
            fitted: Fitted::Predictions,
            chosen: BTreeMap::new(),
            support_cv: None,
        }
    }

    /// The regression's feature names and fit, if the method fitted one.
    pub fn regression(&self) -> Option<(&[String], &RegressionFit)> {
        match &self.fitted {
            Fitted::Regression { features, fit } => Some((features, fit)),
            _ => None,
        }
    }

    /// SINDy's model, if the method is SINDy.
    pub fn sindy(&self) -> Option<&SindyModel> {
        match &self.fitted {
            Fitted::Sindy(model) => Some(model),
            _ => None,
        }
    }

    /// LeARN's cell, if the method is LeARN.
    pub fn into_learn(self) -> Option<CellResult> {
        match self.fitted {
            Fitted::Learn(result) => Some(*result),
            _ => None,
        }
    }
}

/// Meta-trains the LeARN networks for the fold of a cell with a seed.
pub type Train<'t> = dyn Fn(&EvaluationCell, u64) -> Result<MetaTrainedModel> + Sync + 't;

/// The LeARN networks of one cell's fold, by seed, each meta-trained on first use.
pub struct Models<'t> {
    cell: &'t EvaluationCell,
    train: Option<&'t Train<'t>>,
    trained: BTreeMap<u64, Arc<MetaTrainedModel>>,
}

impl<'t> Models<'t> {
    /// The networks of `cell`'s fold meta-trained by `train` (`None`: no method may ask).
    pub fn new(cell: &'t EvaluationCell, train: Option<&'t Train<'t>>) -> Self {
        Self {
            cell,
            train,
            trained: BTreeMap::new(),
        }
    }

    /// With `model` as the networks of `seed`, already meta-trained.
    pub fn with(mut self, seed: u64, model: Arc<MetaTrainedModel>) -> Self {
        self.trained.insert(seed, model);
        self
    }

    fn get(&mut self, seed: u64) -> Result<&MetaTrainedModel> {
        if !self.trained.contains_key(&seed) {
            let train = self.train.ok_or_else(|| EvaluationError::Mismatch {
                what: format!("seed {seed}"),
                message: "no LeARN experiment was loaded to meta-train the networks".to_string(),
            })?;
            let model = train(self.cell, seed)?;
            self.trained.insert(seed, Arc::new(model));
        }
        Ok(&self.trained[&seed])
    }
}

/// One method's evaluation on one cell with one seed: the cell, the seed, the outcomes of the
/// methods before it, and the LeARN networks of the cell's fold.
pub struct Trial<'a, 't> {
    pub cell: &'a EvaluationCell,
    pub seed: u64,
    /// The runner's methods' names, in order.
    names: &'a [&'a str],
    /// The outcomes of the methods before this one, in order.
    done: &'a [Outcome],
    models: &'a mut Models<'t>,
}

impl Trial<'_, '_> {
    /// The LeARN networks of the cell's fold meta-trained with `seed` (trained on first use).
    pub fn model(&mut self, seed: u64) -> Result<&MetaTrainedModel> {
        self.models.get(seed)
    }

    /// The outcomes of the methods before this one, in order.
    pub fn done(&self) -> &[Outcome] {
        self.done
    }

    /// The runner's methods' names, in order.
    pub fn names(&self) -> &[&str] {
        self.names
    }

    /// The positions of the methods `names` (each evaluated before this one, at least one), or
    /// an error saying that every `what` (e.g. `candidate`) of `method` must come before it.
    pub fn earlier(&self, method: &str, names: &[String], what: &str) -> Result<Vec<usize>> {
        let found: Vec<usize> = names
            .iter()
            .filter_map(|name| self.names.iter().position(|n| n == name))
            .filter(|&index| index < self.done.len())
            .collect();
        if found.len() != names.len() || found.is_empty() {
            return Err(EvaluationError::Mismatch {
                what: format!("variant '{method}'"),
                message: format!("every {what} must be declared before it"),
            });
        }
        Ok(found)
    }
}

/// Every method of a list on cells × seeds.
pub struct Runner<'a> {
    methods: Vec<&'a dyn Method>,
    names: Vec<&'a str>,
    /// Meta-trains the networks a method asks for (`None`: none may).
    train: Option<&'a Train<'a>>,
}

impl<'a> Runner<'a> {
    /// The runner of `methods`, in order; `train` meta-trains the LeARN networks.
    pub fn new(
        methods: impl IntoIterator<Item = &'a dyn Method>,
        train: Option<&'a Train<'a>>,
    ) -> Self {
        let methods: Vec<&'a dyn Method> = methods.into_iter().collect();
        let names = methods.iter().map(|m| m.name()).collect();
        Self {
            methods,
            names,
            train,
        }
    }

    /// Whether any method asks for the LeARN networks.
    pub fn needs_meta_training(&self) -> bool {
        self.methods.iter().any(|m| m.needs_meta_training())
    }

    /// Every method on `cell` with `seed`, in order, the networks taken from `models`.
    pub fn evaluate(
        &self,
        cell: &EvaluationCell,
        seed: u64,
        models: &mut Models<'_>,
    ) -> Result<Vec<Outcome>> {
        let mut done: Vec<Outcome> = Vec::with_capacity(self.methods.len());
        for method in &self.methods {
            let outcome = method.evaluate(&mut Trial {
                cell,
                seed,
                names: &self.names,
                done: &done,
                models: &mut *models,
            })?;
            done.push(outcome);
        }
        Ok(done)
    }

    /// Every method on every cell of `cells` with `seed`, in parallel over the cells, telling
    /// `progress` of each cell as it ends; outcomes in the order of `cells`. The networks of
    /// `seed` are meta-trained once, for the fold of the first cell, and serve every cell (the
    /// cells of one work item share their fold).
    pub fn run_cells(
        &self,
        cells: &[Arc<EvaluationCell>],
        seed: u64,
        progress: &dyn Progress,
    ) -> Result<Vec<Vec<Outcome>>> {
        let shared = match (self.needs_meta_training(), self.train, cells.first()) {
            (true, Some(train), Some(first)) => Some(Arc::new(train(first, seed)?)),
            _ => None,
        };
        cells
            .par_iter()
            .map(|cell| {
                let mut models = Models::new(cell, self.train);
                if let Some(model) = &shared {
                    models = models.with(seed, Arc::clone(model));
                }
                let outcomes = self.evaluate(cell, seed, &mut models)?;
                progress.advance(format_args!(
                    "{} {} seed {seed}",
                    cell.formulation.name(),
                    cell.condition.label()
                ));
                Ok(outcomes)
            })
            .collect()
    }
}

/// The cells of `item` among `cells` (formulation by formulation, conditions in table order): its
/// formulation's cell of its condition, or every cell of its formulation.
pub(crate) fn item_cells(
    cells: &[Arc<EvaluationCell>],
    item: &WorkItem,
) -> Result<Vec<Arc<EvaluationCell>>> {
    let found: Vec<Arc<EvaluationCell>> = cells
        .iter()
        .filter(|cell| {
            cell.formulation == item.formulation
                && match &item.cells {
                    Cells::Condition(name) => &cell.condition.name == name,
                    Cells::Every => true,
                }
        })
        .cloned()
        .collect();
    if found.is_empty() {
        return Err(EvaluationError::Mismatch {
            what: item.to_string(),
            message: "names no cell of this run".to_string(),
        });
    }
    Ok(found)
}

/// The paper's LeARN as a method: the networks meta-trained for the cell's fold, adapted online
/// on its support segment, predicting both segments ([`Experiment::evaluate`]).
impl Method for Experiment {
    fn name(&self) -> &str {
        "LeARN"
    }

    fn needs_meta_training(&self) -> bool {
        true
    }

    fn evaluate(&self, trial: &mut Trial<'_, '_>) -> Result<Outcome> {
        let condition = trial.cell.condition.name.clone();
        let seed = trial.seed;
        let result = Experiment::evaluate(self, trial.model(seed)?, &condition)?;
        Ok(Outcome {
            predictions: SegmentPredictions {
                support_prediction: result.support.predictions.clone(),
                query_prediction: result.query.predictions.clone(),
                adaptation: result.summary.adaptation,
                generalisation: result.summary.generalisation,
                support_band: None,
                query_band: None,
            },
            fitted: Fitted::Learn(Box::new(result)),
            chosen: BTreeMap::new(),
            support_cv: None,
        })
    }
}

/// The paper's SINDy baseline as a method: fitted on the support segment, predicting both
/// ([`crate::fit_and_evaluate`]); the seed plays no part.
impl Method for crate::sindy_column::SindyConfig {
    fn name(&self) -> &str {
        "SINDy"
    }

    fn evaluate(&self, trial: &mut Trial<'_, '_>) -> Result<Outcome> {
        let cell = trial.cell;
        let sindy = crate::sindy_column::fit_and_evaluate(self, &cell.support, &cell.query)
            .map_err(|error| crate::error::in_flight(&cell.flight.log.path, error))?;
        Ok(Outcome {
            predictions: SegmentPredictions {
                support_prediction: sindy.support_prediction,
                query_prediction: sindy.query_prediction,
                adaptation: sindy.adaptation,
                generalisation: sindy.generalisation,
                support_band: None,
                query_band: None,
            },
            fitted: Fitted::Sindy(sindy.model),
            chosen: BTreeMap::new(),
            support_cv: None,
        })
    }
}
