//! Writing a run's outputs, rewriting the README's results block, and the check against the paper.

use std::path::{Path, PathBuf};

use learn::Formulation;
use rayon::prelude::*;
use report::{Comparison, PublishedTables, Tolerances, latex, load_tables, markdown};

use crate::cells::figure_file_name;
use crate::config::CheckedRunConfig;
use crate::error::{EvaluationError, Result, write_text};
use crate::run::RunOutcome;
use crate::summary::{StageTiming, Timings};

/// The marker lines between which the README shows the generated tables.
pub const README_BEGIN: &str = "<!-- tables:begin -->";
/// See [`README_BEGIN`].
pub const README_END: &str = "<!-- tables:end -->";

/// Where a run writes: the staging folders of its output set (see the `output_set` crate), whose
/// contents are moved into place only when the whole run has been written.
#[derive(Clone, Debug)]
pub struct OutputPaths {
    /// `tables/*.{md,json}`, `figures/*.svg`, `summary.json` and `timings.json` go here
    /// (`results/` for `make reproduce`).
    pub results_dir: PathBuf,
    /// `<table>.tex` goes here (`paper/tables/` for `make reproduce`).
    pub latex_dir: PathBuf,
}

impl OutputPaths {
    /// `results_dir/tables`.
    pub fn tables_dir(&self) -> PathBuf {
        self.results_dir.join("tables")
    }

    /// `results_dir/figures`.
    pub fn figures_dir(&self) -> PathBuf {
        self.results_dir.join("figures")
    }
}

/// The files a run of `config` writes below its results folder (relative): each table as JSON and
/// Markdown, each figure, `summary.json` and `timings.json`.
pub fn result_files(config: &CheckedRunConfig) -> Vec<PathBuf> {
    let labels: Vec<&str> = config.conditions.evaluation().map(|c| c.label()).collect();
    result_files_of(&config.raw.formulations, &labels)
}

/// [`result_files`] of a run with these tables and condition labels.
pub(crate) fn result_files_of(formulations: &[Formulation], labels: &[&str]) -> Vec<PathBuf> {
    let mut files = Vec::new();
    for formulation in formulations {
        let table = formulation.name();
        files.push(Path::new("tables").join(format!("{table}.json")));
        files.push(Path::new("tables").join(format!("{table}.md")));
        for label in labels {
            files.push(Path::new("figures").join(figure_file_name(table, label)));
        }
    }
    files.extend([PathBuf::from("summary.json"), PathBuf::from("timings.json")]);
    files
}

/// The files a run of `config` writes in its LaTeX folder: `<table>.tex`.
pub fn latex_files(config: &CheckedRunConfig) -> Vec<PathBuf> {
    latex_files_of(&config.raw.formulations)
}

/// [`latex_files`] of a run with these tables.
pub(crate) fn latex_files_of(formulations: &[Formulation]) -> Vec<PathBuf> {
    formulations
        .iter()
        .map(|f| PathBuf::from(format!("{}.tex", f.name())))
        .collect()
}

/// The files `learn ablations` writes below its folder whose names are known before the run (the
/// figures' names depend on the cells, and are checked when the set is committed).
pub fn ablation_files() -> Vec<PathBuf> {
    vec![
        PathBuf::from("ablations.json"),
        PathBuf::from("ablations.md"),
    ]
}

/// Checks, before a run, that `readme` has the results block a run rewrites.
pub fn check_readme(readme: &Path) -> Result<()> {
    results_block(readme, &read_readme(readme)?).map(drop)
}

/// Writes every output of `outcome` into `paths` (staging folders) and returns the files written.
/// The time this takes is recorded in `timings.json` with the run's stages.
pub fn write_outputs(outcome: &RunOutcome, paths: &OutputPaths) -> Result<Vec<PathBuf>> {
    let start = std::time::Instant::now();
    let mut written = Vec::new();
    for table in &outcome.tables {
        let json = paths.tables_dir().join(format!("{}.json", table.table));
        table.save(&json)?;
        let md = paths.tables_dir().join(format!("{}.md", table.table));
        write_text(&md, &markdown(table))?;
        let tex = paths.latex_dir.join(format!("{}.tex", table.table));
        write_text(&tex, &latex(table))?;
        written.extend([json, md, tex]);
    }
    let figures: Vec<PathBuf> = outcome
        .figures
        .par_iter()
        .map(|(name, figure)| {
            let path = paths.figures_dir().join(name);
            figure.save_svg(&path)?;
            Ok(path)
        })
        .collect::<Result<_>>()?;
    written.extend(figures);
    let summary = paths.results_dir.join("summary.json");
    write_text(&summary, &to_json(&outcome.summary)?)?;
    written.push(summary);
    let mut stages = outcome.timings.clone();
    stages.push(StageTiming {
        stage: "write outputs".to_string(),
        seconds: start.elapsed().as_secs_f64(),
    });
    let timings = Timings {
        run: outcome.summary.run.clone(),
        uncommitted_inputs: outcome.uncommitted_inputs,
        threads: crate::worker_threads(),
        total_seconds: stages.iter().map(|s| s.seconds).sum(),
        stages,
    };
    let timings_path = paths.results_dir.join("timings.json");
    write_text(&timings_path, &to_json(&timings)?)?;
    written.push(timings_path);
    Ok(written)
}

/// The README at `readme` with its results block rewritten for `outcome`; `figures_dir` is where
/// the figures will be once committed (linked relative to the README).
pub fn updated_readme(outcome: &RunOutcome, readme: &Path, figures_dir: &Path) -> Result<String> {
    let text = read_readme(readme)?;
    with_block(readme, &text, &readme_block(outcome, figures_dir, readme))
}

/// `text` (of `readme`) with its results block replaced by `block`.
fn with_block(readme: &Path, text: &str, block: &str) -> Result<String> {
    let std::ops::Range {
        start: after_begin,
        end,
    } = results_block(readme, text)?;
    Ok(format!(
        "{}\n\n{}\n{}",
        &text[..after_begin],
        block.trim_end(),
        &text[end..]
    ))
}

fn to_json<T: serde::Serialize>(value: &T) -> Result<String> {
    let mut text =
        serde_json::to_string_pretty(value).map_err(|error| EvaluationError::Config {
            path: PathBuf::from("(output)"),
            field: "serialisation".to_string(),
            message: error.to_string(),
        })?;
    text.push('\n');
    Ok(text)
}

/// The README's generated block ([`report::readme_block`]): every table, then the figures'
/// folder relative to the README, with the first full-dynamics figure shown.
fn readme_block(outcome: &RunOutcome, figures: &Path, readme: &Path) -> String {
    let base = readme.parent().unwrap_or(Path::new(""));
    let relative = figures
        .strip_prefix(base)
        .unwrap_or(figures)
        .display()
        .to_string();
    let example = outcome
        .figures
        .iter()
        .find(|(name, _)| name.starts_with("full_"))
        .map(|(name, _)| (relative.as_str(), name.as_str()));
    report::readme_block(&outcome.tables, example)
}

fn read_readme(readme: &Path) -> Result<String> {
    std::fs::read_to_string(readme).map_err(|source| EvaluationError::Io {
        path: readme.to_path_buf(),
        source,
    })
}

/// The byte range of the generated block in a README's `text`: from the end of [`README_BEGIN`]
/// to the start of [`README_END`].
fn results_block(readme: &Path, text: &str) -> Result<std::ops::Range<usize>> {
    let missing = || EvaluationError::Config {
        path: readme.to_path_buf(),
        field: "results block".to_string(),
        message: format!("needs the lines `{README_BEGIN}` and `{README_END}`, in that order"),
    };
    let begin = text.find(README_BEGIN).ok_or_else(missing)? + README_BEGIN.len();
    let end = begin + text[begin..].find(README_END).ok_or_else(missing)?;
    Ok(begin..end)
}

/// Replaces the text between [`README_BEGIN`] and [`README_END`] in `readme` by `block`.
pub fn update_readme(readme: &Path, block: &str) -> Result<()> {
    let text = read_readme(readme)?;
    let updated = with_block(readme, &text, block)?;
    if updated != text {
        write_text(readme, &updated)?;
    }
    Ok(())
}

/// Compares the results tables in `tables_dir` with the published numbers under the declared
/// tolerances.
pub fn check_paper(tables_dir: &Path, published: &Path, tolerances: &Path) -> Result<Comparison> {
    let tables = load_tables(tables_dir)?;
    let published = PublishedTables::load(published)?;
    let tolerances = Tolerances::load(tolerances)?;
    Ok(Comparison::new(&tables, &published, &tolerances)?)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn readme_block_is_replaced_and_the_rest_kept() {
        let dir = tempfile::Builder::new()
            .prefix("evaluation-readme-")
            .tempdir()
            .unwrap();
        let readme = dir.path().join("README.md");
        let original =
            format!("# Title\n\nintro\n\n{README_BEGIN}\nold\n{README_END}\n\n## After\n");
        std::fs::write(&readme, &original).unwrap();
        update_readme(&readme, "| new | table |\n").unwrap();
        let text = std::fs::read_to_string(&readme).unwrap();
        assert_eq!(
            text,
            format!(
                "# Title\n\nintro\n\n{README_BEGIN}\n\n| new | table |\n{README_END}\n\n## After\n"
            )
        );
        // Idempotent.
        update_readme(&readme, "| new | table |\n").unwrap();
        assert_eq!(std::fs::read_to_string(&readme).unwrap(), text);
        std::fs::write(&readme, "# no markers\n").unwrap();
        let message = update_readme(&readme, "x").unwrap_err().to_string();
        assert!(
            message.contains("README.md") && message.contains("tables:begin"),
            "{message}"
        );
        // The same is found before a run.
        let message = check_readme(&readme).unwrap_err().to_string();
        assert!(message.contains("tables:begin"), "{message}");
        std::fs::write(&readme, &original).unwrap();
        check_readme(&readme).unwrap();
    }
}
