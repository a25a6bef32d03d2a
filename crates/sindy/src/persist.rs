//! Model files: JSON with the names, the library, the optimizer and the non-zero coefficients.
//!
//! ```json
//! {"format": "sindy-model/1", "state": ["x", "y"], "control": ["u"],
//!  "features": ["1", "x", "y", "u", "x^2", ...],
//!  "equations": {"x": {"y": 1.0, "x": -0.1}, "y": {...}},
//!  "library": {"kind": "polynomial", "degree": 2, "constant": true},
//!  "optimizer": {"kind": "stlsq", "threshold": 0.1, "alpha": 0.05, "max_iter": 20},
//!  "derivative": {"kind": "forward"}}
//! ```
//! `equations` maps each state to its non-zero coefficients by feature name; numbers are written
//! with full precision, so a saved and reloaded model predicts bit for bit the same.

use std::collections::BTreeMap;
use std::io::Write;
use std::path::Path;

use crate::differentiation::Derivative;
use faer::Mat;
use serde::{Deserialize, Serialize};

use crate::error::{Result, SindyError};
use crate::library::{FeatureLibrary, LibrarySpec};
use crate::model::SindyModel;
use crate::optimizers::OptimizerSpec;

/// The format tag written in every model file.
pub(crate) const MODEL_FORMAT: &str = "sindy-model/1";

#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct ModelFile {
    format: String,
    state: Vec<String>,
    control: Vec<String>,
    features: Vec<String>,
    equations: BTreeMap<String, BTreeMap<String, f64>>,
    library: LibrarySpec,
    optimizer: OptimizerSpec,
    derivative: Derivative,
}

impl SindyModel {
    /// The model as JSON text (fails for models with custom functions).
    pub fn to_json(&self) -> Result<String> {
        let library = self.library_spec.clone().ok_or_else(|| {
            SindyError::NotSerialisable("the library has custom functions".to_string())
        })?;
        let equations = self
            .state_names
            .iter()
            .enumerate()
            .map(|(i, state)| {
                let terms = self
                    .feature_names
                    .iter()
                    .enumerate()
                    .filter(|&(j, _)| self.coefficients[(i, j)] != 0.0)
                    .map(|(j, feature)| (feature.clone(), self.coefficients[(i, j)]))
                    .collect();
                (state.clone(), terms)
            })
            .collect();
        let file = ModelFile {
            format: MODEL_FORMAT.to_string(),
            state: self.state_names.clone(),
            control: self.control_names.clone(),
            features: self.feature_names.clone(),
            equations,
            library,
            optimizer: self.optimizer,
            derivative: self.derivative,
        };
        Ok(serde_json::to_string_pretty(&file).expect("a model serialises"))
    }

    /// Writes the model to `path`. An existing file is an error unless `overwrite`.
    pub fn save(&self, path: &Path, overwrite: bool) -> Result<()> {
        let text = self.to_json()?;
        let io = |source| SindyError::Io {
            path: path.to_path_buf(),
            source,
        };
        let mut options = std::fs::OpenOptions::new();
        options.write(true);
        if overwrite {
            options.create(true).truncate(true);
        } else {
            options.create_new(true);
        }
        let mut file = options.open(path).map_err(io)?;
        file.write_all(text.as_bytes()).map_err(io)?;
        file.write_all(b"\n").map_err(io)
    }

    /// Reads a model written by [`SindyModel::save`], checking that names, library and
    /// coefficients agree.
    pub fn load(path: &Path) -> Result<Self> {
        let text = bounded_read::read_json_text(path).map_err(|source| SindyError::Io {
            path: path.to_path_buf(),
            source,
        })?;
        Self::from_json(&text, path)
    }

    /// Parses model JSON; `path` only labels errors.
    pub fn from_json(text: &str, path: &Path) -> Result<Self> {
        let error = |field: &str, message: String| SindyError::ModelFile {
            path: path.to_path_buf(),
            field: field.to_string(),
            message,
        };
        let file: ModelFile =
            bounded_read::json::from_str(text).map_err(|e| error(&e.field, e.message))?;
        if file.format != MODEL_FORMAT {
            return Err(error(
                "format",
                format!("'{}', expected '{MODEL_FORMAT}'", file.format),
            ));
        }
        let library = FeatureLibrary::from_spec(&file.library)
            .map_err(|e| error("library", e.to_string()))?;
        file.optimizer
            .checked()
            .map_err(|e| error("optimizer", e.to_string()))?;
        file.derivative
            .validate()
            .map_err(|e| error("derivative", e.to_string()))?;
        let inputs: Vec<&str> = file
            .state
            .iter()
            .chain(&file.control)
            .map(String::as_str)
            .collect();
        if let Some((i, name)) = inputs
            .iter()
            .enumerate()
            .find(|&(i, name)| name.is_empty() || inputs[..i].contains(name))
        {
            let field = if i < file.state.len() {
                "state"
            } else {
                "control"
            };
            return Err(error(
                field,
                format!("'{name}' is empty or named twice among state and control"),
            ));
        }
        let expected = library
            .unique_feature_names(&inputs)
            .map_err(|e| error("library", e.to_string()))?;
        if expected != file.features {
            return Err(error(
                "features",
                format!(
                    "do not match the library {} on the inputs (expected {})",
                    file.library,
                    expected.join(", ")
                ),
            ));
        }
        let mut coefficients = Mat::zeros(file.state.len(), file.features.len());
        if let Some(unknown) = file.equations.keys().find(|k| !file.state.contains(k)) {
            return Err(error("equations", format!("'{unknown}' is not a state")));
        }
        for (i, state) in file.state.iter().enumerate() {
            let terms = file
                .equations
                .get(state)
                .ok_or_else(|| error("equations", format!("no equation for state '{state}'")))?;
            for (feature, &value) in terms {
                let j = file
                    .features
                    .iter()
                    .position(|f| f == feature)
                    .ok_or_else(|| {
                        error(
                            &format!("equations.{state}"),
                            format!("'{feature}' is not a feature"),
                        )
                    })?;
                coefficients[(i, j)] = value;
            }
        }
        Ok(SindyModel {
            state_names: file.state,
            control_names: file.control,
            feature_names: file.features,
            library,
            library_spec: Some(file.library),
            optimizer: file.optimizer,
            derivative: file.derivative,
            coefficients,
        })
    }
}
