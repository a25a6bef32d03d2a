//! The paper's published numbers (`paper/published.json`).

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use crate::error::{ReportError, Result, read_json};
use crate::table::{Method, MethodPair, Metric, serde_name};

/// The largest value accepted as a published mean squared error: the paper's are below 2, and a
/// larger number is a typing error (`1e308`), not a result.
pub const MAX_PUBLISHED_MSE: f64 = 1e6;

/// `{"source": "...", "tables": {"translational": {"35wind": {"sindy": {...}, "learn": {...}}}}}`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PublishedTables {
    /// Where the numbers come from.
    pub source: String,
    /// Table name, then the condition as the paper prints it.
    pub tables: BTreeMap<String, BTreeMap<String, MethodPair>>,
    /// The file the numbers were read from (empty when built in code), for error messages.
    #[serde(skip)]
    pub path: PathBuf,
}

impl PublishedTables {
    /// Reads `published.json` and checks it: at least one table, every table with at least one
    /// condition, every value a plausible mean squared error (finite, non-negative, at most
    /// `MAX_PUBLISHED_MSE`). Errors name the file and the field.
    pub fn load(path: &Path) -> Result<Self> {
        let published: Self = read_json(path)?;
        let published = Self {
            path: path.to_path_buf(),
            ..published
        };
        published.validate()?;
        Ok(published)
    }

    fn validate(&self) -> Result<()> {
        let error = |field: String, message: String| ReportError::Json {
            path: self.path.clone(),
            field,
            message,
        };
        if self.tables.is_empty() {
            return Err(error(
                "tables".to_string(),
                "no table: there is nothing to check".to_string(),
            ));
        }
        for (table, conditions) in &self.tables {
            if conditions.is_empty() {
                return Err(error(
                    format!("tables.{table}"),
                    "no condition: there is nothing to check in this table".to_string(),
                ));
            }
            for (condition, pair) in conditions {
                for method in Method::ALL {
                    for metric in Metric::ALL {
                        let value = pair.get(method).get(metric);
                        if !(value.is_finite() && (0.0..=MAX_PUBLISHED_MSE).contains(&value)) {
                            return Err(error(
                                format!(
                                    "tables.{table}.{condition}.{}.{}",
                                    serde_name(method),
                                    serde_name(metric)
                                ),
                                format!(
                                    "{value:?} is not a published mean squared error (a finite \
                                     number from 0 to {MAX_PUBLISHED_MSE:e})"
                                ),
                            ));
                        }
                    }
                }
            }
        }
        Ok(())
    }

    /// The published numbers of one cell row, if the paper has them.
    pub fn get(&self, table: &str, condition: &str) -> Option<&MethodPair> {
        self.tables.get(table)?.get(condition)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reads_the_committed_file() {
        let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../paper/published.json");
        let published = PublishedTables::load(&path).unwrap();
        let cell = published.get("attitude", "70psin20").unwrap();
        assert_eq!(cell.learn.generalisation, 0.493);
        assert_eq!(cell.sindy.adaptation, 0.578);
        assert!(published.get("attitude", "200wind").is_none());
    }

    #[test]
    fn nothing_to_check_and_implausible_values_are_refused_naming_the_field() {
        let dir = tempfile::Builder::new()
            .prefix("report-published-")
            .tempdir()
            .unwrap();
        let path = dir.path().join("published.json");
        let message = |text: &str| {
            std::fs::write(&path, text).unwrap();
            PublishedTables::load(&path).unwrap_err().to_string()
        };
        let cell = |value: &str| {
            format!(
                r#"{{"source": "s", "tables": {{"translational": {{"35wind":
                {{"sindy": {{"adapt": 0.1, "gen": {value}}}, "learn": {{"adapt": 0.1, "gen": 0.2}}}}}}}}}}"#
            )
        };
        std::fs::write(&path, cell("0.2")).unwrap();
        assert!(PublishedTables::load(&path).is_ok());
        for value in ["-0.1", "1e308", "2e17"] {
            let text = message(&cell(value));
            assert!(
                text.contains(&format!(
                    "published.json: tables.translational.35wind.sindy.gen: {value} is not a \
                     published mean squared error"
                )),
                "{value}: {text}"
            );
        }
        let text = message(r#"{"source": "s", "tables": {"translational": {}}}"#);
        assert!(
            text.contains("published.json: tables.translational: no condition"),
            "{text}"
        );
        let text = message(r#"{"source": "s", "tables": {}}"#);
        assert!(text.contains("published.json: tables: no table"), "{text}");
    }
}
