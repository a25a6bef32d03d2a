//! The results of one table: per evaluation condition, the MSE of each method, and the published
//! values beside them.

use std::collections::BTreeMap;
use std::path::Path;

use serde::{Deserialize, Serialize};

use crate::error::{ReportError, Result, read_json, write_text};
use crate::published::PublishedTables;

/// The paper's tables in the paper's order; other names sort after them, alphabetically.
pub const PAPER_TABLES: [&str; 3] = ["translational", "attitude", "full"];

/// Adaptation and generalisation mean squared error of one method on one flight.
///
/// Adaptation MSE: the adapted (or fitted) model on the support segment it was adapted on.
/// Generalisation MSE: the same model, frozen, on the query segment.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Mse {
    #[serde(rename = "adapt")]
    pub adaptation: f64,
    #[serde(rename = "gen")]
    pub generalisation: f64,
}

impl Mse {
    /// Adaptation and generalisation MSE.
    pub const fn new(adaptation: f64, generalisation: f64) -> Self {
        Self {
            adaptation,
            generalisation,
        }
    }

    /// The value of one metric.
    pub fn get(&self, metric: Metric) -> f64 {
        match metric {
            Metric::Adaptation => self.adaptation,
            Metric::Generalisation => self.generalisation,
        }
    }

    /// `self − other`, metric by metric.
    pub fn minus(&self, other: &Mse) -> Mse {
        Mse {
            adaptation: self.adaptation - other.adaptation,
            generalisation: self.generalisation - other.generalisation,
        }
    }
}

/// The two methods of the paper's tables.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Method {
    Sindy,
    Learn,
}

impl Method {
    /// Both methods in the paper's column order.
    pub const ALL: [Method; 2] = [Method::Sindy, Method::Learn];

    /// The name printed in tables and figures.
    pub fn display_name(&self) -> &'static str {
        match self {
            Self::Sindy => "SINDy",
            Self::Learn => "LeARN",
        }
    }
}

/// The two error metrics of the paper's tables.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize, Deserialize)]
pub enum Metric {
    #[serde(rename = "adapt")]
    Adaptation,
    #[serde(rename = "gen")]
    Generalisation,
}

impl Metric {
    /// Both metrics in the paper's column order.
    pub const ALL: [Metric; 2] = [Metric::Adaptation, Metric::Generalisation];

    /// The column heading (the paper's abbreviation).
    pub fn display_name(&self) -> &'static str {
        match self {
            Self::Adaptation => "Adapt.",
            Self::Generalisation => "Gen.",
        }
    }
}

/// One value per method (published numbers, or differences from them).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MethodPair {
    pub sindy: Mse,
    pub learn: Mse,
}

impl MethodPair {
    /// The errors of one method.
    pub fn get(&self, method: Method) -> &Mse {
        match method {
            Method::Sindy => &self.sindy,
            Method::Learn => &self.learn,
        }
    }
}

/// One row of a table: one evaluation condition.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Row {
    /// The condition as the paper prints it, e.g. `70psin20`.
    pub condition: String,
    pub sindy: Mse,
    pub learn: Mse,
    /// The paper's numbers for this condition, when it has them.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub published: Option<MethodPair>,
    /// Ours minus published, when published numbers exist.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub difference: Option<MethodPair>,
    /// Further methods (ablations, other models), by name; shown in Markdown, never compared.
    #[serde(default, skip_serializing_if = "BTreeMap::is_empty")]
    pub variants: BTreeMap<String, Mse>,
    /// Any other sibling key written by a later tool, kept as is.
    #[serde(flatten)]
    pub extra: BTreeMap<String, serde_json::Value>,
}

impl Row {
    /// A row with our two methods and nothing else.
    pub fn new(condition: impl Into<String>, sindy: Mse, learn: Mse) -> Self {
        Row {
            condition: condition.into(),
            sindy,
            learn,
            published: None,
            difference: None,
            variants: BTreeMap::new(),
            extra: BTreeMap::new(),
        }
    }

    /// Our errors of one method.
    pub fn ours(&self, method: Method) -> &Mse {
        match method {
            Method::Sindy => &self.sindy,
            Method::Learn => &self.learn,
        }
    }

    /// Whether `method` is the better one (lower MSE) in `metric` for this row, as the paper marks
    /// it in bold: compared at the three decimals printed, a tie marks both.
    pub fn is_best(&self, method: Method, metric: Metric) -> bool {
        let printed = |m: Method| (self.ours(m).get(metric) * 1000.0).round();
        Method::ALL
            .iter()
            .all(|other| printed(method) <= printed(*other))
    }
}

/// One of the paper's tables (one formulation): the JSON written to `results/tables/<table>.json`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ResultsTable {
    /// The formulation, e.g. `translational`.
    pub table: String,
    /// The protocol that produced the numbers, e.g. `leave-condition-out`.
    pub protocol: String,
    pub rows: Vec<Row>,
    /// Lines printed under the table (facts about the cells that the numbers alone do not show).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub notes: Vec<String>,
}

impl ResultsTable {
    /// Fills `published` and `difference` of every row from the paper's numbers, where it has them.
    pub fn attach_published(&mut self, published: &PublishedTables) {
        for row in &mut self.rows {
            row.published = published.get(&self.table, &row.condition).copied();
            row.difference = row.published.map(|paper| MethodPair {
                sindy: row.sindy.minus(&paper.sindy),
                learn: row.learn.minus(&paper.learn),
            });
        }
    }

    /// The table as pretty JSON (with a final newline).
    pub fn to_json(&self) -> String {
        let mut text = serde_json::to_string_pretty(self).expect("results serialise");
        text.push('\n');
        text
    }

    /// Reads a table written by [`ResultsTable::to_json`].
    pub fn load(path: &Path) -> Result<Self> {
        let table: Self = read_json(path)?;
        table.validate(path)?;
        Ok(table)
    }

    /// Writes the JSON to `path`.
    pub fn save(&self, path: &Path) -> Result<()> {
        write_text(path, &self.to_json())
    }

    fn validate(&self, path: &Path) -> Result<()> {
        for (index, row) in self.rows.iter().enumerate() {
            if let Some(earlier) = self.rows[..index]
                .iter()
                .position(|other| other.condition == row.condition)
            {
                return Err(ReportError::Json {
                    path: path.to_path_buf(),
                    field: format!("rows[{index}].condition"),
                    message: format!("'{}' is also rows[{earlier}]", row.condition),
                });
            }
            for method in Method::ALL {
                for metric in Metric::ALL {
                    let value = row.ours(method).get(metric);
                    if !value.is_finite() || value < 0.0 {
                        return Err(ReportError::Json {
                            path: path.to_path_buf(),
                            field: format!(
                                "rows[{index}] ({}).{}.{}",
                                row.condition,
                                serde_name(method),
                                serde_name(metric)
                            ),
                            message: format!("{value} is not a mean squared error"),
                        });
                    }
                }
            }
        }
        Ok(())
    }
}

/// The JSON spelling of a method or metric.
pub(crate) fn serde_name<T: Serialize>(value: T) -> String {
    serde_json::to_value(value)
        .ok()
        .and_then(|v| v.as_str().map(str::to_string))
        .unwrap_or_default()
}

/// Sort key putting the paper's tables first, in the paper's order.
pub(crate) fn table_order(name: &str) -> (usize, String) {
    let position = PAPER_TABLES
        .iter()
        .position(|t| *t == name)
        .unwrap_or(PAPER_TABLES.len());
    (position, name.to_string())
}

/// Reads every `*.json` table of a directory, the paper's tables first in the paper's order.
pub fn load_tables(dir: &Path) -> Result<Vec<ResultsTable>> {
    let entries = std::fs::read_dir(dir).map_err(|source| ReportError::Io {
        path: dir.to_path_buf(),
        source,
    })?;
    let mut paths = Vec::new();
    for entry in entries {
        let path = entry
            .map_err(|source| ReportError::Io {
                path: dir.to_path_buf(),
                source,
            })?
            .path();
        if path.extension().is_some_and(|e| e == "json") {
            paths.push(path);
        }
    }
    // In name order, so that an error names the same file whatever order the directory lists.
    paths.sort();
    let mut tables: Vec<ResultsTable> = Vec::with_capacity(paths.len());
    // tables[k] is read from paths[k].
    for path in &paths {
        let table = ResultsTable::load(path)?;
        // Two files for one table: which one was meant is unknowable, and the choice would
        // depend on the files' names.
        if let Some(earlier) = tables.iter().position(|t| t.table == table.table) {
            return Err(ReportError::Json {
                path: path.clone(),
                field: "table".to_string(),
                message: format!(
                    "'{}' is also the table of {} (one file per table)",
                    table.table,
                    paths[earlier].display()
                ),
            });
        }
        tables.push(table);
    }
    if tables.is_empty() {
        return Err(ReportError::Invalid {
            what: dir.display().to_string(),
            message: "no results table (*.json) here: run `make reproduce` first".to_string(),
        });
    }
    tables.sort_by_key(|t| table_order(&t.table));
    Ok(tables)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn mse(adaptation: f64, generalisation: f64) -> Mse {
        Mse::new(adaptation, generalisation)
    }

    #[test]
    fn json_has_the_documented_shape_and_keeps_unknown_keys() {
        let mut row = Row::new("35wind", mse(0.1, 0.2), mse(0.3, 0.4));
        row.variants
            .insert("first-order".to_string(), mse(0.5, 0.6));
        row.extra
            .insert("note".to_string(), serde_json::json!({"k": 1}));
        let table = ResultsTable {
            table: "translational".to_string(),
            protocol: "leave-condition-out".to_string(),
            rows: vec![row],
            notes: Vec::new(),
        };
        let value: serde_json::Value = serde_json::from_str(&table.to_json()).unwrap();
        assert_eq!(value["rows"][0]["sindy"]["gen"], 0.2);
        assert_eq!(value["rows"][0]["learn"]["adapt"], 0.3);
        assert_eq!(value["rows"][0]["variants"]["first-order"]["gen"], 0.6);
        assert_eq!(value["rows"][0]["note"]["k"], 1);
        let back: ResultsTable = serde_json::from_value(value).unwrap();
        assert_eq!(back, table);
    }

    #[test]
    fn best_is_the_lower_printed_value_and_ties_mark_both() {
        let row = Row::new("c", mse(0.1231, 0.5), mse(0.1234, 0.4));
        assert!(row.is_best(Method::Sindy, Metric::Adaptation));
        assert!(row.is_best(Method::Learn, Metric::Adaptation));
        assert!(!row.is_best(Method::Sindy, Metric::Generalisation));
        assert!(row.is_best(Method::Learn, Metric::Generalisation));
    }

    #[test]
    fn a_table_in_two_files_is_an_error_naming_both() {
        let tmp = tempfile::Builder::new()
            .prefix("report-two-files-")
            .tempdir()
            .unwrap();
        // A folder that does not exist yet: saving the first table makes it.
        let dir = tmp.path().join("tables");
        let table = |generalisation: f64| ResultsTable {
            table: "translational".to_string(),
            protocol: "p".to_string(),
            rows: vec![Row::new("35wind", mse(0.1, generalisation), mse(0.3, 0.4))],
            notes: Vec::new(),
        };
        table(0.2).save(&dir.join("translational.json")).unwrap();
        assert_eq!(load_tables(&dir).unwrap().len(), 1);
        table(5.0).save(&dir.join("zzz.json")).unwrap();
        let message = load_tables(&dir).unwrap_err().to_string();
        assert!(
            message.contains("zzz.json: table: 'translational' is also the table of")
                && message.contains("translational.json (one file per table)"),
            "{message}"
        );
    }

    #[test]
    fn negative_errors_are_rejected_with_the_field() {
        let tmp = tempfile::Builder::new()
            .prefix("report-table-")
            .tempdir()
            .unwrap();
        // In a folder that does not exist yet: saving makes it.
        let path = tmp.path().join("tables/t.json");
        let table = ResultsTable {
            table: "full".to_string(),
            protocol: "p".to_string(),
            rows: vec![Row::new("70wind", mse(0.1, -1.0), mse(0.3, 0.4))],
            notes: Vec::new(),
        };
        table.save(&path).unwrap();
        let message = ResultsTable::load(&path).unwrap_err().to_string();
        assert!(
            message.contains("t.json")
                && message.contains("70wind")
                && message.contains("sindy.gen"),
            "{message}"
        );
        // A condition twice would be compared, and counted, twice.
        let twice = ResultsTable {
            rows: vec![
                Row::new("70wind", mse(0.1, 0.2), mse(0.3, 0.4)),
                Row::new("70wind", mse(0.1, 0.2), mse(0.3, 0.4)),
            ],
            ..table
        };
        twice.save(&path).unwrap();
        let message = ResultsTable::load(&path).unwrap_err().to_string();
        assert!(
            message.contains("rows[1].condition") && message.contains("rows[0]"),
            "{message}"
        );
    }
}
