//! Text renderings of a [`ResultsTable`]: Markdown (README, `results/tables/*.md`) and LaTeX in the
//! paper's booktabs layout (`paper/tables/*.tex`). JSON is [`ResultsTable::to_json`].

use std::collections::BTreeSet;
use std::fmt::Write;

use crate::table::{Method, Metric, ResultsTable, Row};

/// The paper's caption of a table, e.g. `Translational Dynamics Estimation Error: SINDy vs. LeARN`.
pub fn caption(table: &str) -> String {
    let mut name = table.to_string();
    if let Some(first) = name.get_mut(0..1) {
        first.make_ascii_uppercase();
    }
    format!("{name} Dynamics Estimation Error: SINDy vs. LeARN")
}

/// The paper's LaTeX label of a table.
pub fn latex_label(table: &str) -> String {
    match table {
        "full" => "tab:full_performance_comparison".to_string(),
        other => format!("tab:{other}_comparison"),
    }
}

/// A value with three decimals, as the paper prints.
fn value(v: f64) -> String {
    format!("{v:.3}")
}

/// A signed difference with three decimals; one that rounds to zero prints as `+0.000`.
fn signed(d: f64) -> String {
    if (d * 1000.0).round() == 0.0 {
        "+0.000".to_string()
    } else {
        format!("{d:+.3}")
    }
}

/// Names of the variants present in any row, sorted.
fn variant_names(table: &ResultsTable) -> Vec<String> {
    table
        .rows
        .iter()
        .flat_map(|row| row.variants.keys().cloned())
        .collect::<BTreeSet<_>>()
        .into_iter()
        .collect()
}

fn markdown_cell(row: &Row, method: Method, metric: Metric) -> String {
    let ours = value(row.ours(method).get(metric));
    let mut cell = if row.is_best(method, metric) {
        format!("**{ours}**")
    } else {
        ours
    };
    if let (Some(published), Some(difference)) = (&row.published, &row.difference) {
        let _ = write!(
            cell,
            " ({}; {})",
            value(published.get(method).get(metric)),
            signed(difference.get(method).get(metric))
        );
    }
    cell
}

/// The README's generated results block: every table in Markdown, then a pointer to the figures
/// with `example` (the folder as linked from the README, and a figure's file name) shown inline.
pub fn readme_block(tables: &[ResultsTable], example: Option<(&str, &str)>) -> String {
    let mut block = String::new();
    for table in tables {
        block.push_str(&markdown(table));
        block.push('\n');
    }
    if let Some((folder, name)) = example {
        block.push_str(&format!(
            "The paper's qualitative figure, one per table and condition, is in `{folder}/`; for \
             example the full dynamics in the first condition:\n\n![{name}]({folder}/{name})\n"
        ));
    }
    block
}

/// The table in Markdown: a caption line, a legend line and one row per condition. Each cell holds
/// our value (bold when it is the better of SINDy and LeARN for that metric) followed by the published value and
/// the difference; variants, if any, follow as plain columns; the table's notes, if any, follow it
/// as paragraphs.
pub fn markdown(table: &ResultsTable) -> String {
    let variants = variant_names(table);
    let mut out = String::new();
    let _ = writeln!(
        out,
        "**{}** (protocol: `{}`)\n",
        caption(&table.table),
        table.protocol
    );
    out.push_str(
        "Each cell: ours (published; ours − published). Bold: the better of SINDy and LeARN for \
         each metric, as in the paper",
    );
    if !variants.is_empty() {
        out.push_str("; the variant columns after them are not compared");
    }
    out.push_str(".\n\n");
    out.push_str("| Condition |");
    for method in Method::ALL {
        for metric in Metric::ALL {
            let _ = write!(
                out,
                " {} {} |",
                method.display_name(),
                metric.display_name()
            );
        }
    }
    for name in &variants {
        for metric in Metric::ALL {
            let _ = write!(out, " {name} {} |", metric.display_name());
        }
    }
    out.push_str("\n|---|");
    out.push_str(&"---:|".repeat(4 + 2 * variants.len()));
    out.push('\n');
    for row in &table.rows {
        let _ = write!(out, "| {} |", row.condition);
        for method in Method::ALL {
            for metric in Metric::ALL {
                let _ = write!(out, " {} |", markdown_cell(row, method, metric));
            }
        }
        for name in &variants {
            for metric in Metric::ALL {
                let text = row
                    .variants
                    .get(name)
                    .map(|mse| value(mse.get(metric)))
                    .unwrap_or_else(|| "–".to_string());
                let _ = write!(out, " {text} |");
            }
        }
        out.push('\n');
    }
    for note in &table.notes {
        let _ = write!(out, "\n{note}\n");
    }
    out
}

/// Escapes the characters LaTeX treats specially in a condition name.
fn latex_escape(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    for c in text.chars() {
        match c {
            '_' | '%' | '&' | '#' | '$' | '{' | '}' => {
                out.push('\\');
                out.push(c);
            }
            '~' => out.push_str("\\textasciitilde{}"),
            '^' => out.push_str("\\textasciicircum{}"),
            '\\' => out.push_str("\\textbackslash{}"),
            other => out.push(other),
        }
    }
    out
}

/// The table as the paper typesets it (a `table` float with `\small`, booktabs rules and the
/// paper's header), ready to `\input`. Under each condition's row, a `paper` row gives the published
/// value and, in brackets, ours minus published. Needs the `booktabs` and `multirow` packages.
pub fn latex(table: &ResultsTable) -> String {
    let mut out = String::new();
    let _ = writeln!(
        out,
        "% Generated by `make reproduce` (protocol: {}); do not edit.",
        table.protocol
    );
    out.push_str("\\begin{table}[h]\n\\centering\n");
    let _ = writeln!(out, "\\caption{{{}}}", caption(&table.table));
    let _ = writeln!(out, "\\label{{{}}}", latex_label(&table.table));
    out.push_str("\\small\n\\begin{tabular}{l cccc}\n\\toprule\n");
    out.push_str(
        "\\multirow{2}{*}{\\textbf{Condition}} & \\multicolumn{2}{c}{\\textbf{SINDy}} & \
         \\multicolumn{2}{c}{\\textbf{LeARN (Ours)}} \\\\ \n",
    );
    out.push_str("\\cmidrule(r){2-3} \\cmidrule(l){4-5}\n");
    out.push_str("& \\textit{Adapt.} & \\textit{Gen.} & \\textit{Adapt.} & \\textit{Gen.} \\\\ \n");
    out.push_str("\\midrule\n");
    for (index, row) in table.rows.iter().enumerate() {
        if index > 0 && row.published.is_some() {
            out.push_str("\\addlinespace\n");
        }
        let _ = write!(out, "{:<8}", latex_escape(&row.condition));
        for method in Method::ALL {
            for metric in Metric::ALL {
                let ours = value(row.ours(method).get(metric));
                if row.is_best(method, metric) {
                    let _ = write!(out, " & \\textbf{{{ours}}}");
                } else {
                    let _ = write!(out, " & {ours}");
                }
            }
        }
        out.push_str(" \\\\ \n");
        if let (Some(published), Some(difference)) = (&row.published, &row.difference) {
            out.push_str("{\\scriptsize\\textit{paper}}");
            for method in Method::ALL {
                for metric in Metric::ALL {
                    let _ = write!(
                        out,
                        " & {{\\scriptsize {} (${}$)}}",
                        value(published.get(method).get(metric)),
                        signed(difference.get(method).get(metric))
                    );
                }
            }
            out.push_str(" \\\\ \n");
        }
    }
    out.push_str("\\bottomrule\n\\end{tabular}\n\\end{table}\n");
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::published::PublishedTables;
    use crate::table::{MethodPair, Mse};

    fn mse(adaptation: f64, generalisation: f64) -> Mse {
        Mse::new(adaptation, generalisation)
    }

    fn sample() -> ResultsTable {
        let mut table = ResultsTable {
            table: "translational".to_string(),
            protocol: "leave-condition-out".to_string(),
            rows: vec![
                Row::new("35wind", mse(0.1564, 0.1941), mse(0.150, 0.2101)),
                Row::new("new_wind", mse(0.3, 0.4), mse(0.2, 0.5)),
            ],
            notes: vec![
                "LeARN query samples outside the meta-training input range: 35wind 0 of 10."
                    .to_string(),
            ],
        };
        let mut published = PublishedTables {
            source: "test".to_string(),
            tables: Default::default(),
            path: Default::default(),
        };
        published
            .tables
            .entry("translational".to_string())
            .or_default()
            .insert(
                "35wind".to_string(),
                MethodPair {
                    sindy: mse(0.156, 0.194),
                    learn: mse(0.155, 0.208),
                },
            );
        table.attach_published(&published);
        table
    }

    #[test]
    fn markdown_marks_the_better_method_and_shows_published_and_difference() {
        let text = markdown(&sample());
        let row = text.lines().find(|l| l.starts_with("| 35wind")).unwrap();
        assert_eq!(
            row,
            "| 35wind | 0.156 (0.156; +0.000) | **0.194** (0.194; +0.000) | \
             **0.150** (0.155; -0.005) | 0.210 (0.208; +0.002) |"
        );
        // A condition the paper does not have: no published value, still compared for bold.
        let new = text.lines().find(|l| l.starts_with("| new_wind")).unwrap();
        assert_eq!(new, "| new_wind | 0.300 | **0.400** | **0.200** | 0.500 |");
        assert!(text.starts_with("**Translational Dynamics Estimation Error: SINDy vs. LeARN**"));
        assert!(
            text.contains(
                "Bold: the better of SINDy and LeARN for each metric, as in the paper.\n"
            )
        );
        // The note is a paragraph after the last row.
        assert!(text.ends_with(
            "| new_wind | 0.300 | **0.400** | **0.200** | 0.500 |\n\n\
             LeARN query samples outside the meta-training input range: 35wind 0 of 10.\n"
        ));
        assert!(!latex(&sample()).contains("meta-training input range"));
    }

    #[test]
    fn markdown_shows_variants_as_extra_columns() {
        let mut table = sample();
        table.rows[0]
            .variants
            .insert("first-order".to_string(), mse(0.25, 0.35));
        let text = markdown(&table);
        assert!(text.contains("| first-order Adapt. | first-order Gen. |"));
        assert!(text.contains("as in the paper; the variant columns after them are not compared."));
        assert!(
            text.lines()
                .any(|l| l.starts_with("| new_wind") && l.ends_with("| – | – |"))
        );
        assert!(
            text.lines()
                .any(|l| l.starts_with("| 35wind") && l.ends_with("| 0.250 | 0.350 |"))
        );
    }

    #[test]
    fn latex_follows_the_paper_layout() {
        let text = latex(&sample());
        assert!(
            text.contains("\\caption{Translational Dynamics Estimation Error: SINDy vs. LeARN}")
        );
        assert!(text.contains("\\label{tab:translational_comparison}"));
        assert!(text.contains("\\begin{tabular}{l cccc}"));
        assert!(text.contains("35wind   & 0.156 & \\textbf{0.194} & \\textbf{0.150} & 0.210 \\\\"));
        assert!(text.contains("{\\scriptsize 0.155 ($-0.005$)}"));
        assert!(text.contains("new\\_wind"));
        for rule in [
            "\\toprule",
            "\\midrule",
            "\\bottomrule",
            "\\cmidrule(r){2-3}",
        ] {
            assert_eq!(text.matches(rule).count(), 1, "{rule}");
        }
        assert_eq!(latex_label("full"), "tab:full_performance_comparison");
    }
}
