//! The regression check against the paper: every published cell, our value, the tolerance declared
//! for it in `paper/tolerances.json`, and whether it holds.

use std::fmt::Write;
use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use crate::error::{ReportError, Result, read_json};
use crate::published::PublishedTables;
use crate::table::{Method, Metric, ResultsTable, serde_name, table_order};

/// Which differences a tolerance allows.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Direction {
    /// |ours − published| ≤ tolerance: a reproduction of the same computation.
    TwoSided,
    /// ours − published ≤ tolerance: an error lower than the paper's is never a regression.
    NotWorse,
}

/// One tolerance, applying to every cell it matches. Unset fields match anything; among the rules
/// matching a cell, the most specific one (most fields set) applies, the later one on a tie.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ToleranceRule {
    pub method: Method,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub table: Option<String>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub condition: Option<String>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub metric: Option<Metric>,
    pub tolerance: f64,
    pub direction: Direction,
    /// Why this bound: the evidence it rests on.
    #[serde(default)]
    pub reason: String,
}

impl ToleranceRule {
    fn matches(&self, method: Method, table: &str, condition: &str, metric: Metric) -> bool {
        self.method == method
            && self.table.as_deref().is_none_or(|t| t == table)
            && self.condition.as_deref().is_none_or(|c| c == condition)
            && self.metric.is_none_or(|m| m == metric)
    }

    fn specificity(&self) -> usize {
        usize::from(self.table.is_some())
            + usize::from(self.condition.is_some())
            + usize::from(self.metric.is_some())
    }
}

/// The whole `paper/tolerances.json`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Tolerances {
    pub description: String,
    pub rules: Vec<ToleranceRule>,
    /// Measurements the rules rest on (free-form, kept for the reader).
    #[serde(default)]
    pub evidence: serde_json::Value,
    /// The file the rules were read from (empty when built in code), for error messages.
    #[serde(skip)]
    pub path: PathBuf,
}

impl Tolerances {
    /// Reads and checks `tolerances.json`.
    pub fn load(path: &Path) -> Result<Self> {
        let tolerances: Self = read_json(path)?;
        let error = |field: String, message: String| ReportError::Json {
            path: path.to_path_buf(),
            field,
            message,
        };
        for (index, rule) in tolerances.rules.iter().enumerate() {
            if !(rule.tolerance.is_finite() && rule.tolerance >= 0.0) {
                return Err(error(
                    format!("rules[{index}].tolerance"),
                    format!("{} is not a finite non-negative number", rule.tolerance),
                ));
            }
            // Two rules for exactly the same cells: which one was meant is unknowable.
            let selector =
                |r: &ToleranceRule| (r.method, r.table.clone(), r.condition.clone(), r.metric);
            if let Some(earlier) = tolerances.rules[..index]
                .iter()
                .position(|other| selector(other) == selector(rule))
            {
                return Err(error(
                    format!("rules[{index}]"),
                    format!("covers exactly the cells of rules[{earlier}]"),
                ));
            }
        }
        Ok(Self {
            path: path.to_path_buf(),
            ..tolerances
        })
    }

    /// Refuses a rule naming a table or a condition the published numbers do not have (a typing
    /// error such as `translatonal` would make the rule apply to nothing, silently). A rule's
    /// condition must be one of its table's, or of any table when the rule names none.
    pub fn check_names(&self, published: &PublishedTables) -> Result<()> {
        let error = |field: String, message: String| ReportError::Json {
            path: self.path.clone(),
            field,
            message,
        };
        let list = |names: Vec<&String>| {
            names
                .iter()
                .map(|n| n.as_str())
                .collect::<Vec<_>>()
                .join(", ")
        };
        for (index, rule) in self.rules.iter().enumerate() {
            let tables: Vec<(&String, _)> = match &rule.table {
                Some(table) => match published.tables.get_key_value(table) {
                    Some(entry) => vec![entry],
                    None => {
                        return Err(error(
                            format!("rules[{index}].table"),
                            format!(
                                "'{table}' is not a table of {} (tables: {})",
                                published.path.display(),
                                list(published.tables.keys().collect())
                            ),
                        ));
                    }
                },
                None => published.tables.iter().collect(),
            };
            if let Some(condition) = &rule.condition
                && !tables.iter().any(|(_, c)| c.contains_key(condition))
            {
                let mut known: Vec<&String> = tables.iter().flat_map(|(_, c)| c.keys()).collect();
                known.sort();
                known.dedup();
                let within = match &rule.table {
                    Some(table) => format!("table '{table}'"),
                    None => "any table".to_string(),
                };
                return Err(error(
                    format!("rules[{index}].condition"),
                    format!(
                        "'{condition}' is not a condition of {within} in {} (conditions: {})",
                        published.path.display(),
                        list(known)
                    ),
                ));
            }
        }
        Ok(())
    }

    /// The rule that applies to one cell, if any.
    pub fn rule_for(
        &self,
        method: Method,
        table: &str,
        condition: &str,
        metric: Metric,
    ) -> Option<&ToleranceRule> {
        self.rules
            .iter()
            .filter(|rule| rule.matches(method, table, condition, metric))
            // max_by_key returns the last maximum: the later rule wins a tie.
            .max_by_key(|rule| rule.specificity())
    }
}

/// The outcome of one cell.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum CellStatus {
    /// Within tolerance.
    Pass,
    /// Outside tolerance.
    Regression,
    /// The paper has the cell, our results do not.
    Missing,
    /// Our results have a condition the paper does not: shown, not checked.
    Unpublished,
}

/// One cell of the side-by-side comparison.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct CellComparison {
    pub table: String,
    pub condition: String,
    pub method: Method,
    pub metric: Metric,
    pub ours: Option<f64>,
    pub published: Option<f64>,
    pub tolerance: Option<f64>,
    pub direction: Option<Direction>,
    pub status: CellStatus,
}

impl CellComparison {
    /// Ours minus published, when both exist.
    pub fn difference(&self) -> Option<f64> {
        Some(self.ours? - self.published?)
    }
}

/// Every cell of every table, compared.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Comparison {
    pub cells: Vec<CellComparison>,
    /// Table name and protocol of the results compared.
    pub protocols: Vec<(String, String)>,
}

impl Comparison {
    /// Compares `results` with every published cell. A published cell without a tolerance rule is
    /// an error (the declaration must be complete), not a silent pass.
    pub fn new(
        results: &[ResultsTable],
        published: &PublishedTables,
        tolerances: &Tolerances,
    ) -> Result<Self> {
        let mut table_names: Vec<&str> = results.iter().map(|t| t.table.as_str()).collect();
        // A table the paper has no numbers for would pass unchecked: the file is incomplete.
        if let Some(name) = table_names
            .iter()
            .find(|name| !published.tables.contains_key(**name))
        {
            return Err(ReportError::Json {
                path: published.path.clone(),
                field: "tables".to_string(),
                message: format!("no published numbers for the results table '{name}'"),
            });
        }
        tolerances.check_names(published)?;
        for name in published.tables.keys() {
            if !table_names.contains(&name.as_str()) {
                table_names.push(name);
            }
        }
        table_names.sort_by_key(|name| table_order(name));
        let mut cells = Vec::new();
        for table_name in table_names {
            let ours = results.iter().find(|t| t.table == table_name);
            let mut conditions: Vec<&str> = ours
                .map(|t| t.rows.iter().map(|r| r.condition.as_str()).collect())
                .unwrap_or_default();
            for condition in published.tables.get(table_name).into_iter().flatten() {
                if !conditions.contains(&condition.0.as_str()) {
                    conditions.push(condition.0);
                }
            }
            for condition in conditions {
                let row = ours.and_then(|t| t.rows.iter().find(|r| r.condition == condition));
                let paper = published.get(table_name, condition);
                for method in Method::ALL {
                    for metric in Metric::ALL {
                        let ours_value = row.map(|r| r.ours(method).get(metric));
                        let published_value = paper.map(|p| p.get(method).get(metric));
                        let rule = match published_value {
                            Some(_) => Some(
                                tolerances
                                    .rule_for(method, table_name, condition, metric)
                                    .ok_or_else(|| ReportError::Json {
                                        path: tolerances.path.clone(),
                                        field: "rules".to_string(),
                                        message: format!(
                                            "no rule covers {table_name} {condition} {} {}",
                                            serde_name(method),
                                            serde_name(metric)
                                        ),
                                    })?,
                            ),
                            None => None,
                        };
                        let status = match (ours_value, published_value, rule) {
                            (None, _, _) => CellStatus::Missing,
                            (Some(_), None, _) | (_, _, None) => CellStatus::Unpublished,
                            (Some(ours), Some(paper), Some(rule)) => {
                                if within(ours - paper, rule.tolerance, rule.direction) {
                                    CellStatus::Pass
                                } else {
                                    CellStatus::Regression
                                }
                            }
                        };
                        cells.push(CellComparison {
                            table: table_name.to_string(),
                            condition: condition.to_string(),
                            method,
                            metric,
                            ours: ours_value,
                            published: published_value,
                            tolerance: rule.map(|r| r.tolerance),
                            direction: rule.map(|r| r.direction),
                            status,
                        });
                    }
                }
            }
        }
        // A check of nothing is no check: say so instead of "0 of 0 within tolerance".
        if cells.iter().all(|c| c.published.is_none()) {
            return Err(ReportError::Json {
                path: published.path.clone(),
                field: "tables".to_string(),
                message: "no published cell to check".to_string(),
            });
        }
        let protocols = results
            .iter()
            .map(|t| (t.table.clone(), t.protocol.clone()))
            .collect();
        Ok(Comparison { cells, protocols })
    }

    /// Whether no cell regressed and none is missing.
    pub fn passed(&self) -> bool {
        self.failures().next().is_none()
    }

    /// The cells that fail the check.
    pub fn failures(&self) -> impl Iterator<Item = &CellComparison> {
        self.cells
            .iter()
            .filter(|c| matches!(c.status, CellStatus::Regression | CellStatus::Missing))
    }

    /// The side-by-side table printed by `learn check-paper`, then a one-line verdict.
    pub fn render_text(&self) -> String {
        let mut out = String::new();
        let mut current = "";
        for cell in &self.cells {
            if cell.table != current {
                current = &cell.table;
                let protocol = self
                    .protocols
                    .iter()
                    .find(|(t, _)| t == current)
                    .map(|(_, p)| p.as_str())
                    .unwrap_or("no results");
                let _ = writeln!(out, "\n{current} (protocol: {protocol})");
                let _ = writeln!(
                    out,
                    "  {:<10} {:<6} {:<7} {:>8} {:>8} {:>8}  {:<11} status",
                    "condition", "method", "metric", "ours", "paper", "diff", "tolerance"
                );
            }
            let number = |v: Option<f64>| v.map_or("–".to_string(), |v| format!("{v:.4}"));
            let tolerance = match (cell.tolerance, cell.direction) {
                (Some(t), Some(Direction::TwoSided)) => format!("±{t:.3}"),
                (Some(t), Some(Direction::NotWorse)) => format!("≤ +{t:.3}"),
                _ => "–".to_string(),
            };
            let status = match cell.status {
                CellStatus::Pass => "ok",
                CellStatus::Regression => "REGRESSION",
                CellStatus::Missing => "MISSING",
                CellStatus::Unpublished => "not in paper",
            };
            let _ = writeln!(
                out,
                "  {:<10} {:<6} {:<7} {:>8} {:>8} {:>8}  {:<11} {status}",
                cell.condition,
                cell.method.display_name(),
                cell.metric.display_name(),
                number(cell.ours),
                number(cell.published),
                cell.difference()
                    .map_or("–".to_string(), |d| format!("{d:+.4}")),
                tolerance,
            );
        }
        let checked = self
            .cells
            .iter()
            .filter(|c| c.status != CellStatus::Unpublished)
            .count();
        let failed = self.failures().count();
        let _ = writeln!(
            out,
            "\n{} of {checked} published cells within tolerance{}",
            checked - failed,
            if failed == 0 {
                String::new()
            } else {
                format!("; {failed} failed")
            }
        );
        out
    }
}

fn within(difference: f64, tolerance: f64, direction: Direction) -> bool {
    // A hair of slack so that a bound written with three decimals holds for values printed so.
    let slack = 1e-12;
    match direction {
        Direction::TwoSided => difference.abs() <= tolerance + slack,
        Direction::NotWorse => difference <= tolerance + slack,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::table::{MethodPair, Mse, Row};

    fn mse(adaptation: f64, generalisation: f64) -> Mse {
        Mse::new(adaptation, generalisation)
    }

    fn published() -> PublishedTables {
        let mut tables = std::collections::BTreeMap::new();
        tables.insert(
            "translational".to_string(),
            [(
                "35wind".to_string(),
                MethodPair {
                    sindy: mse(0.156, 0.194),
                    learn: mse(0.155, 0.208),
                },
            )]
            .into_iter()
            .collect(),
        );
        PublishedTables {
            source: "test".to_string(),
            tables,
            path: PathBuf::from("published.json"),
        }
    }

    fn tolerances() -> Tolerances {
        serde_json::from_value(serde_json::json!({
            "description": "test",
            "rules": [
                {"method": "sindy", "tolerance": 0.01, "direction": "two-sided"},
                {"method": "learn", "tolerance": 0.03, "direction": "not-worse"},
                {"method": "learn", "table": "translational", "metric": "adapt",
                 "tolerance": 0.001, "direction": "two-sided"}
            ]
        }))
        .unwrap()
    }

    fn results(sindy: Mse, learn: Mse) -> Vec<ResultsTable> {
        vec![ResultsTable {
            table: "translational".to_string(),
            protocol: "p".to_string(),
            rows: vec![
                Row::new("35wind", sindy, learn),
                Row::new("extra", mse(1.0, 1.0), mse(1.0, 1.0)),
            ],
            notes: Vec::new(),
        }]
    }

    #[test]
    fn the_most_specific_rule_applies() {
        let t = tolerances();
        let rule = t
            .rule_for(Method::Learn, "translational", "35wind", Metric::Adaptation)
            .unwrap();
        assert_eq!(rule.tolerance, 0.001);
        let rule = t
            .rule_for(
                Method::Learn,
                "translational",
                "35wind",
                Metric::Generalisation,
            )
            .unwrap();
        assert_eq!(rule.tolerance, 0.03);
    }

    #[test]
    fn within_tolerance_passes_and_unpublished_rows_are_not_checked() {
        let comparison = Comparison::new(
            &results(mse(0.165, 0.185), mse(0.1555, 0.10)),
            &published(),
            &tolerances(),
        )
        .unwrap();
        assert!(comparison.passed(), "{}", comparison.render_text());
        assert_eq!(
            comparison
                .cells
                .iter()
                .filter(|c| c.status == CellStatus::Unpublished)
                .count(),
            4
        );
        assert!(
            comparison
                .render_text()
                .contains("4 of 4 published cells within tolerance")
        );
    }

    #[test]
    fn a_worse_or_far_cell_is_a_regression() {
        // SINDy too low (two-sided), LeARN gen. too high (not-worse).
        let comparison = Comparison::new(
            &results(mse(0.140, 0.194), mse(0.155, 0.2385)),
            &published(),
            &tolerances(),
        )
        .unwrap();
        assert!(!comparison.passed());
        let failed: Vec<(Method, Metric)> = comparison
            .failures()
            .map(|c| (c.method, c.metric))
            .collect();
        assert_eq!(
            failed,
            vec![
                (Method::Sindy, Metric::Adaptation),
                (Method::Learn, Metric::Generalisation)
            ]
        );
        let text = comparison.render_text();
        assert!(
            text.contains("REGRESSION") && text.contains("2 failed"),
            "{text}"
        );
    }

    #[test]
    fn a_missing_table_fails_and_a_missing_rule_is_an_error() {
        let comparison = Comparison::new(&[], &published(), &tolerances()).unwrap();
        assert_eq!(comparison.failures().count(), 4);
        assert!(
            comparison
                .failures()
                .all(|c| c.status == CellStatus::Missing)
        );
        let only_sindy: Tolerances = serde_json::from_value(serde_json::json!({
            "description": "test",
            "rules": [{"method": "sindy", "tolerance": 0.01, "direction": "two-sided"}]
        }))
        .unwrap();
        let message = Comparison::new(
            &results(mse(0.1, 0.1), mse(0.1, 0.1)),
            &published(),
            &only_sindy,
        )
        .unwrap_err()
        .to_string();
        assert!(
            message.contains("translational 35wind learn adapt"),
            "{message}"
        );
    }

    #[test]
    fn the_files_must_be_complete_and_unambiguous() {
        // Results for a table the published file does not have: an error naming that file.
        let mut other = results(mse(0.1, 0.1), mse(0.1, 0.1));
        other[0].table = "attitude".to_string();
        let message = Comparison::new(&other, &published(), &tolerances())
            .unwrap_err()
            .to_string();
        assert!(
            message.contains("published.json") && message.contains("'attitude'"),
            "{message}"
        );
        // Two rules for exactly the same cells.
        let dir = tempfile::Builder::new()
            .prefix("report-tolerances-")
            .tempdir()
            .unwrap();
        let path = dir.path().join("tolerances.json");
        let mut value = serde_json::to_value(tolerances()).unwrap();
        let first = value["rules"][0].clone();
        value["rules"].as_array_mut().unwrap().push(first);
        std::fs::write(&path, value.to_string()).unwrap();
        let message = Tolerances::load(&path).unwrap_err().to_string();
        assert!(
            message.contains("tolerances.json: rules[3]")
                && message.contains("exactly the cells of rules[0]"),
            "{message}"
        );
        value["rules"].as_array_mut().unwrap().pop();
        std::fs::write(&path, value.to_string()).unwrap();
        assert_eq!(Tolerances::load(&path).unwrap().path, path);
    }

    #[test]
    fn a_rule_naming_an_unknown_table_or_condition_is_refused() {
        let results = results(mse(0.156, 0.194), mse(0.155, 0.208));
        let with_rule = |rule: serde_json::Value| {
            let mut t = tolerances();
            t.path = PathBuf::from("tolerances.json");
            t.rules.push(serde_json::from_value(rule).unwrap());
            Comparison::new(&results, &published(), &t)
                .unwrap_err()
                .to_string()
        };
        let message = with_rule(
            serde_json::json!({"method": "sindy", "table": "translatonal",
            "tolerance": 0.1, "direction": "two-sided"}),
        );
        assert!(
            message.contains("tolerances.json: rules[3].table: 'translatonal' is not a table of")
                && message.contains("published.json (tables: translational)"),
            "{message}"
        );
        let message = with_rule(serde_json::json!({"method": "sindy", "condition": "35Wind",
            "tolerance": 0.1, "direction": "two-sided"}));
        assert!(
            message.contains("tolerances.json: rules[3].condition: '35Wind' is not a condition")
                && message.contains("(conditions: 35wind)"),
            "{message}"
        );
        let message = with_rule(
            serde_json::json!({"method": "sindy", "table": "translational",
            "condition": "70wind", "tolerance": 0.1, "direction": "two-sided"}),
        );
        assert!(
            message.contains("rules[3].condition: '70wind' is not a condition of table"),
            "{message}"
        );
    }

    #[test]
    fn checking_no_published_cell_is_an_error() {
        let mut empty = published();
        empty
            .tables
            .insert("translational".to_string(), Default::default());
        let message = Comparison::new(
            &results(mse(0.1, 0.1), mse(0.1, 0.1)),
            &empty,
            &tolerances(),
        )
        .unwrap_err()
        .to_string();
        assert!(
            message.contains("published.json: tables: no published cell to check"),
            "{message}"
        );
    }
}
