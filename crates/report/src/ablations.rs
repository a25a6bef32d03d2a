//! The ablation tables (`results/ablations/ablations.md`): every variant of the variants file on
//! every cell, beside the published columns and the targets' noise floor. The rows
//! ([`AblationRow`]) are the numbers `ablations.json` records; [`AblationTables`] adds what the
//! Markdown says about the run (its text, seeds, headline and variants).

use std::collections::BTreeMap;

use serde::{Deserialize, Serialize};

use crate::table::{MethodPair, Mse};

/// The noise-floor estimates of one segment's forward-difference targets (computed by
/// `evaluation::forward_difference_noise_floor`), in the tables' MSE unit.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct NoiseFloor {
    /// Mean square of forward difference minus the Savitzky–Golay derivative.
    pub upper: f64,
    /// Twice the negative lag-one autocovariance of that residual (clipped to [0, upper]).
    pub lower: f64,
}

/// Mean and spread of one variant on one cell over the seeds.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct VariantCell {
    #[serde(rename = "adapt")]
    pub adaptation: f64,
    #[serde(rename = "gen")]
    pub generalisation: f64,
    /// Sample standard deviation over seeds (0 for one seed).
    pub adapt_std: f64,
    pub gen_std: f64,
    pub seeds: Vec<SeedCell>,
}

/// One choice a variant made inside the support segment. Written as the bare value (`0.001`,
/// `"lag-ridge-cv"`), as `ablations.json` always had it.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(untagged)]
pub enum Choice {
    /// The penalty chosen for one output.
    Penalty(f64),
    /// The candidate a `select` variant chose, by name.
    Variant(String),
}

/// One seed of one variant on one cell.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SeedCell {
    pub seed: u64,
    #[serde(rename = "adapt")]
    pub adaptation: f64,
    #[serde(rename = "gen")]
    pub generalisation: f64,
    /// Mean over outputs of the best support cross-validation MSE (variants that fit a
    /// regression).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub support_cv: Option<f64>,
    /// What was chosen inside the support segment: per output the penalty, and for `select` the
    /// candidate (under `variant`).
    pub chosen: BTreeMap<String, Choice>,
    /// For bagged variants: the fraction of query targets inside the predictive band.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub query_band_coverage: Option<f64>,
}

/// One row of the ablation table: one formulation on one condition.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct AblationRow {
    pub table: String,
    pub condition: String,
    /// The paper's numbers, when it has them, and the target min(SINDy gen, LeARN gen).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub published: Option<MethodPair>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub target: Option<f64>,
    /// Our SINDy with the paper's settings (the run configuration's).
    pub sindy: Mse,
    /// Noise floor of the forward-difference targets on each segment.
    pub noise_floor_support: NoiseFloor,
    pub noise_floor_query: NoiseFloor,
    pub variants: BTreeMap<String, VariantCell>,
    /// The headline model fitted with the first seed, one equation per output, terms ordered by
    /// their share of the prediction's variance on the support segment (largest first).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub headline_equations: Vec<String>,
}

/// A variant as the tables list it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct VariantNote<'a> {
    pub name: &'a str,
    pub description: &'a str,
}

/// Everything the ablation tables show: the rows, and what the text says about the run.
#[derive(Clone, Debug, PartialEq)]
pub struct AblationTables<'a> {
    /// The variants file's name and description.
    pub name: &'a str,
    pub description: &'a str,
    /// The protocol line.
    pub protocol: &'a str,
    pub seeds: &'a [u64],
    /// The variant declared as the headline column.
    pub headline: &'a str,
    /// The variant whose equations describe the headline (itself, or the member of an average
    /// that fits a regression).
    pub headline_equations_of: &'a str,
    /// The variant whose band the figures draw, if any.
    pub figure_variant: Option<&'a str>,
    /// Every variant, in declaration order (the columns of the full tables).
    pub variants: Vec<VariantNote<'a>>,
    pub rows: &'a [AblationRow],
}

/// The ablation tables as Markdown: the headline comparison, then every variant's generalisation
/// and adaptation MSE (mean ± standard deviation over seeds) per formulation.
pub fn ablations_markdown(tables: &AblationTables) -> String {
    let mut out = introduction(tables);
    headline_section(tables, &mut out);
    noise_floor_section(tables, &mut out);
    if let Some(name) = tables.figure_variant {
        band_section(tables, name, &mut out);
    }
    best_variant_section(tables, &mut out);
    for metric in ["gen", "adapt"] {
        every_variant_section(tables, metric, &mut out);
    }
    if tables.rows.iter().any(|r| !r.headline_equations.is_empty()) {
        equations_section(tables, &mut out);
    }
    out.push_str("## Variants\n\n");
    for variant in &tables.variants {
        out.push_str(&format!("- `{}`: {}\n", variant.name, variant.description));
    }
    out
}

/// The title, the description, the protocol and seeds, and how the noise floor is estimated.
fn introduction(tables: &AblationTables) -> String {
    let seeds = tables
        .seeds
        .iter()
        .map(u64::to_string)
        .collect::<Vec<_>>()
        .join(", ");
    format!(
        "# Ablations: {}\n\n{}\n\nProtocol: {}. Seeds: {seeds}. MSE = mean over samples and state \
         dimensions; `±` is the standard deviation over seeds (0 for deterministic variants).\n\n\
         Noise floor of the forward-difference target on the query segment (`evaluation::forward_difference_noise_floor`): \
         `lower–upper`, where upper = mean square of forward difference minus a Savitzky–Golay(21, 3) \
         derivative (counts motion faster than 0.4 s as noise) and lower = twice the negative lag-one \
         autocovariance of that residual.\n\n",
        tables.name, tables.description, tables.protocol
    )
}

/// The headline variant against min(published SINDy gen, published LeARN gen), and in how many
/// cells it is below that target.
fn headline_section(tables: &AblationTables, out: &mut String) {
    out.push_str(&format!(
        "## Headline: `{}` against min(published SINDy gen, published LeARN gen)\n\n",
        tables.headline
    ));
    out.push_str("| table | condition | published SINDy gen | published LeARN gen | target | ours SINDy gen | headline gen | vs target | below target | noise floor (query) | headline / floor upper |\n");
    out.push_str("|---|---|---|---|---|---|---|---|---|---|---|\n");
    let mut wins = 0;
    for row in tables.rows {
        let headline = &row.variants[tables.headline];
        let (pub_sindy, pub_learn) = row
            .published
            .map(|p| {
                (
                    format!("{:.3}", p.sindy.generalisation),
                    format!("{:.3}", p.learn.generalisation),
                )
            })
            .unwrap_or(("–".to_string(), "–".to_string()));
        let (target, versus, below) = match row.target {
            Some(target) => {
                let below = headline.generalisation < target;
                wins += usize::from(below);
                (
                    format!("{target:.3}"),
                    format!("{:+.1} %", 100.0 * (headline.generalisation / target - 1.0)),
                    if below { "yes" } else { "**no**" }.to_string(),
                )
            }
            None => ("–".to_string(), "–".to_string(), "–".to_string()),
        };
        out.push_str(&format!(
            "| {} | {} | {pub_sindy} | {pub_learn} | {target} | {:.3} | {:.3} ± {:.3} | {versus} | {below} | {:.3}–{:.3} | {:.2} |\n",
            row.table,
            row.condition,
            row.sindy.generalisation,
            headline.generalisation,
            headline.gen_std,
            row.noise_floor_query.lower,
            row.noise_floor_query.upper,
            headline.generalisation / row.noise_floor_query.upper,
        ));
    }
    out.push_str(&format!(
        "\n`{}` is below the target in {wins} of {} cells.\n\n",
        tables.headline,
        tables.rows.iter().filter(|r| r.target.is_some()).count()
    ));
}

/// Each method's generalisation MSE divided by the query floor's upper estimate.
fn noise_floor_section(tables: &AblationTables, out: &mut String) {
    out.push_str(
        "## Distance above the noise floor: generalisation MSE ÷ the query floor's upper estimate\n\n\
         1.00 would mean nothing but (upper-estimate) noise is left; the lower estimate shows how \
         much of that upper estimate may itself be fast, predictable motion.\n\n\
         | table | condition | floor (lower–upper) | published SINDy | published LeARN | ours SINDy | headline | best variant |\n\
         |---|---|---|---|---|---|---|---|\n",
    );
    for row in tables.rows {
        let floor = row.noise_floor_query.upper;
        let ratio = |value: f64| format!("{:.2}", value / floor);
        let (pub_sindy, pub_learn) = row
            .published
            .map(|p| (ratio(p.sindy.generalisation), ratio(p.learn.generalisation)))
            .unwrap_or(("–".to_string(), "–".to_string()));
        let best = row
            .variants
            .values()
            .map(|v| v.generalisation)
            .fold(f64::INFINITY, f64::min);
        out.push_str(&format!(
            "| {} | {} | {:.3}–{floor:.3} | {pub_sindy} | {pub_learn} | {} | {} | {} |\n",
            row.table,
            row.condition,
            row.noise_floor_query.lower,
            ratio(row.sindy.generalisation),
            ratio(row.variants[tables.headline].generalisation),
            ratio(best),
        ));
    }
    out.push('\n');
}

/// The share of query targets inside the predictive band of the figures' variant `name`.
fn band_section(tables: &AblationTables, name: &str, out: &mut String) {
    out.push_str(&format!(
        "## Predictive band of `{name}` (drawn in `figures/`): share of query targets inside it\n\n\
         Band = ensemble mean ± 2·√(members' variance + the output's support CV MSE); about 0.95 \
         is expected if the errors were Gaussian and the query behaved like the support.\n\n\
         | table | condition | coverage (mean over seeds) |\n|---|---|---|\n"
    ));
    for row in tables.rows {
        let values: Vec<f64> = row.variants[name]
            .seeds
            .iter()
            .filter_map(|s| s.query_band_coverage)
            .collect();
        if !values.is_empty() {
            let mean = values.iter().sum::<f64>() / values.len() as f64;
            out.push_str(&format!(
                "| {} | {} | {mean:.3} |\n",
                row.table, row.condition
            ));
        }
    }
    out.push('\n');
}

/// The variant with the lowest generalisation MSE per cell (descriptive: chosen on the query).
fn best_variant_section(tables: &AblationTables, out: &mut String) {
    out.push_str("## Best variant per cell (generalisation MSE, mean over seeds)\n\n");
    out.push_str("| table | condition | best variant | gen | target | vs target |\n|---|---|---|---|---|---|\n");
    for row in tables.rows {
        let (name, cell) = row
            .variants
            .iter()
            .min_by(|a, b| a.1.generalisation.total_cmp(&b.1.generalisation))
            .expect("at least one variant");
        let versus = row
            .target
            .map(|t| format!("{:+.1} %", 100.0 * (cell.generalisation / t - 1.0)))
            .unwrap_or_else(|| "–".to_string());
        let target = row
            .target
            .map(|t| format!("{t:.3}"))
            .unwrap_or_else(|| "–".to_string());
        out.push_str(&format!(
            "| {} | {} | `{name}` | {:.3} | {target} | {versus} |\n",
            row.table, row.condition, cell.generalisation
        ));
    }
    out.push_str("\n(Picking the best variant per cell by its query error is itself a choice made on the query segment: this table is descriptive. The headline column above is declared in `experiments/variants.json`; its description says when it was chosen.)\n\n");
}

/// Every variant's `metric` (`gen` or `adapt`) MSE, mean ± standard deviation over seeds.
fn every_variant_section(tables: &AblationTables, metric: &str, out: &mut String) {
    out.push_str(&format!(
        "## Every variant, {metric} MSE (mean ± std over seeds)\n\n"
    ));
    let names: Vec<&str> = tables.variants.iter().map(|v| v.name).collect();
    out.push_str("| table | condition | ours SINDy |");
    for name in &names {
        out.push_str(&format!(" `{name}` |"));
    }
    out.push_str("\n|---|---|---|");
    out.push_str(&"---|".repeat(names.len()));
    out.push('\n');
    for row in tables.rows {
        let sindy = if metric == "gen" {
            row.sindy.generalisation
        } else {
            row.sindy.adaptation
        };
        out.push_str(&format!(
            "| {} | {} | {sindy:.3} |",
            row.table, row.condition
        ));
        for name in &names {
            let cell = &row.variants[*name];
            let (mean, std) = if metric == "gen" {
                (cell.generalisation, cell.gen_std)
            } else {
                (cell.adaptation, cell.adapt_std)
            };
            out.push_str(&format!(" {mean:.3} ± {std:.3} |"));
        }
        out.push('\n');
    }
    out.push('\n');
}

/// The headline's equations with the first seed, each cut to its five largest terms.
fn equations_section(tables: &AblationTables, out: &mut String) {
    let name = tables.headline_equations_of;
    let role = if name == tables.headline {
        String::new()
    } else {
        format!(
            " (the regression member of the headline `{}`)",
            tables.headline
        )
    };
    out.push_str(&format!(
        "## `{name}` equations{role} (seed {}), the five largest terms\n\n\
         Terms ordered by standardised coefficient; every term is in `ablations.json`.\n\n",
        tables.seeds.first().copied().unwrap_or_default()
    ));
    for row in tables.rows {
        out.push_str(&format!("- {} {}:\n", row.table, row.condition));
        for equation in &row.headline_equations {
            let shown = shorten(equation, 5);
            out.push_str(&format!("  - `{shown}`\n"));
        }
    }
    out.push('\n');
}

/// The intercept and the first `terms` terms of an equation of `headline_equations`.
fn shorten(equation: &str, terms: usize) -> String {
    let words: Vec<&str> = equation.split(' ').collect();
    // "out = b" then groups of three words: sign, coefficient, feature.
    let keep = (3 + 3 * terms).min(words.len());
    let mut text = words[..keep].join(" ");
    if keep < words.len() {
        text.push_str(" …");
    }
    text
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn choices_are_written_as_bare_values_and_read_back() {
        let chosen: BTreeMap<String, Choice> = [
            ("vdot_x".to_string(), Choice::Penalty(0.001)),
            ("vdot_y".to_string(), Choice::Penalty(1.0)),
            (
                "variant".to_string(),
                Choice::Variant("lag-ridge-cv".to_string()),
            ),
        ]
        .into();
        let text = serde_json::to_string(&chosen).unwrap();
        assert_eq!(
            text,
            r#"{"variant":"lag-ridge-cv","vdot_x":0.001,"vdot_y":1.0}"#
        );
        let read: BTreeMap<String, Choice> = serde_json::from_str(&text).unwrap();
        assert_eq!(read, chosen);
    }

    #[test]
    fn equations_are_shortened_to_their_largest_terms() {
        let equation = "vdot_x = 0.1000 + 2.0000 a - 1.0000 b + 0.5000 c";
        assert_eq!(
            shorten(equation, 2),
            "vdot_x = 0.1000 + 2.0000 a - 1.0000 b …"
        );
        assert_eq!(shorten(equation, 3), equation);
    }

    fn cell(generalisation: f64, coverage: Option<f64>) -> VariantCell {
        VariantCell {
            adaptation: generalisation / 2.0,
            generalisation,
            adapt_std: 0.0,
            gen_std: 0.01,
            seeds: vec![SeedCell {
                seed: 3,
                adaptation: generalisation / 2.0,
                generalisation,
                support_cv: None,
                chosen: BTreeMap::new(),
                query_band_coverage: coverage,
            }],
        }
    }

    #[test]
    fn the_tables_compare_the_headline_with_the_target_and_list_every_variant() {
        let floor = NoiseFloor {
            upper: 0.5,
            lower: 0.25,
        };
        let rows = [AblationRow {
            table: "full".to_string(),
            condition: "35wind".to_string(),
            published: Some(MethodPair {
                sindy: Mse::new(1.0, 2.0),
                learn: Mse::new(0.5, 1.5),
            }),
            target: Some(1.5),
            sindy: Mse::new(0.9, 1.8),
            noise_floor_support: floor,
            noise_floor_query: floor,
            variants: BTreeMap::from([
                ("bag".to_string(), cell(1.2, Some(0.9))),
                ("ridge".to_string(), cell(1.0, None)),
            ]),
            headline_equations: vec!["vdot_x = 0.1000 + 2.0000 a".to_string()],
        }];
        let tables = AblationTables {
            name: "t",
            description: "d",
            protocol: "p",
            seeds: &[3, 4],
            headline: "ridge",
            headline_equations_of: "ridge",
            figure_variant: Some("bag"),
            variants: vec![
                VariantNote {
                    name: "ridge",
                    description: "a ridge",
                },
                VariantNote {
                    name: "bag",
                    description: "bagged",
                },
            ],
            rows: &rows,
        };
        let markdown = ablations_markdown(&tables);
        assert!(markdown.starts_with("# Ablations: t\n\nd\n\nProtocol: p. Seeds: 3, 4."));
        assert!(markdown.contains(
            "| full | 35wind | 2.000 | 1.500 | 1.500 | 1.800 | 1.000 ± 0.010 | -33.3 % | yes | 0.250–0.500 | 2.00 |"
        ));
        assert!(markdown.contains("`ridge` is below the target in 1 of 1 cells."));
        assert!(markdown.contains("| full | 35wind | 0.900 |\n"));
        assert!(markdown.contains("| full | 35wind | `ridge` | 1.000 | 1.500 | -33.3 % |"));
        assert!(markdown.contains("| full | 35wind | 1.800 | 1.000 ± 0.010 | 1.200 ± 0.010 |"));
        assert!(markdown.contains("## `ridge` equations (seed 3)"));
        assert!(markdown.ends_with("## Variants\n\n- `ridge`: a ridge\n- `bag`: bagged\n"));
    }
}
