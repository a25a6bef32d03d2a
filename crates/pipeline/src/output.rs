//! Writing a run's outputs, rewriting the README's results block, and the check against the paper.

use std::path::{Path, PathBuf};

use rayon::prelude::*;
use report::{Comparison, PublishedTables, Tolerances, latex, load_tables, markdown};

use crate::error::{PipelineError, Result, write_text};
use crate::run::RunOutcome;
use crate::summary::{StageTiming, Timings};

/// The marker lines between which the README shows the generated tables.
pub const README_BEGIN: &str = "<!-- tables:begin -->";
/// See [`README_BEGIN`].
pub const README_END: &str = "<!-- tables:end -->";

/// Where a run writes.
#[derive(Clone, Debug)]
pub struct OutputPaths {
    /// `tables/*.{md,json}`, `figures/*.svg`, `summary.json` and `timings.json` go here
    /// (`results/` for `make reproduce`).
    pub results_dir: PathBuf,
    /// `<table>.tex` goes here (`paper/tables/` for `make reproduce`).
    pub latex_dir: PathBuf,
    /// A README whose block between [`README_BEGIN`] and [`README_END`] is replaced by the tables.
    pub readme: Option<PathBuf>,
}

impl OutputPaths {
    /// Checks, before a run, that its outputs can be written: each directory is created and
    /// written to (a probe file, removed again), and the README, if any, has the results block.
    /// A run then never fails at its end for a reason known at its start.
    pub fn check(&self) -> Result<()> {
        for dir in [&self.results_dir, &self.latex_dir] {
            check_writable(dir)?;
        }
        if let Some(readme) = &self.readme {
            results_block(readme, &read_readme(readme)?)?;
        }
        Ok(())
    }

    /// `results_dir/tables`.
    pub fn tables_dir(&self) -> PathBuf {
        self.results_dir.join("tables")
    }

    /// `results_dir/figures`.
    pub fn figures_dir(&self) -> PathBuf {
        self.results_dir.join("figures")
    }
}

/// What a run will write, known before it runs: files by name, and directories in which every
/// file of some extensions is written or removed (a run's tables and figures, whose names depend
/// on the conditions, and the stale ones of an earlier run).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct PlannedOutputs {
    /// Files written (or rewritten), and the probe files of the writability checks.
    pub files: Vec<PathBuf>,
    /// A directory and the extensions of the files the run writes or removes directly in it.
    pub owned: Vec<(PathBuf, Vec<&'static str>)>,
}

impl PlannedOutputs {
    /// Whether `path` would be written or removed according to `same_file` (a comparison that
    /// sees through spellings of the path): the output it would be, for an error message.
    pub fn clobbers(
        &self,
        path: &Path,
        same_file: &dyn Fn(&Path, &Path) -> bool,
    ) -> Option<String> {
        if let Some(file) = self.files.iter().find(|file| same_file(path, file)) {
            return Some(file.display().to_string());
        }
        // An existing input is where its links lead: a link elsewhere to a file in an owned
        // directory is that file.
        let target = path.canonicalize().unwrap_or_else(|_| path.to_path_buf());
        let parent = target.parent().filter(|p| !p.as_os_str().is_empty());
        let parent = parent.unwrap_or(Path::new("."));
        let extension = target.extension().and_then(|e| e.to_str())?;
        self.owned
            .iter()
            .find(|(dir, extensions)| extensions.contains(&extension) && same_file(parent, dir))
            .map(|(dir, _)| format!("every *.{extension} in {} (replaced)", dir.display()))
    }
}

const PROBE: &str = ".learn-write-check";

impl OutputPaths {
    /// The files a run producing the tables `tables` writes and removes (see [`write_outputs`]):
    /// the README is not among them (it is an input too, updated in place).
    pub fn planned(&self, tables: &[&str]) -> PlannedOutputs {
        let mut files: Vec<PathBuf> = tables
            .iter()
            .map(|table| self.latex_dir.join(format!("{table}.tex")))
            .collect();
        files.extend([
            self.results_dir.join("summary.json"),
            self.results_dir.join("timings.json"),
            self.results_dir.join(PROBE),
            self.latex_dir.join(PROBE),
        ]);
        PlannedOutputs {
            files,
            owned: vec![
                (self.tables_dir(), vec!["json", "md"]),
                (self.figures_dir(), vec!["svg"]),
            ],
        }
    }
}

/// The files `learn ablations` writes under `dir` (see [`crate::write_ablations`]).
pub fn planned_ablations(dir: &Path) -> PlannedOutputs {
    PlannedOutputs {
        files: vec![
            dir.join("ablations.json"),
            dir.join("ablations.md"),
            dir.join(PROBE),
            dir.join("figures").join(PROBE),
        ],
        owned: vec![(dir.join("figures"), vec!["svg"])],
    }
}

/// Creates `dir` and writes a probe file in it (removed again): a run then never fails at its end
/// for an output directory it could have checked at its start.
fn check_writable(dir: &Path) -> Result<()> {
    let probe = dir.join(PROBE);
    write_text(&probe, "")?;
    std::fs::remove_file(&probe).map_err(|source| PipelineError::Io {
        path: probe.clone(),
        source,
    })
}

/// Checks, before `learn ablations` fits anything, that [`crate::write_ablations`] can write
/// under `dir` (`ablations.{json,md}` there, figures in `dir/figures`), as
/// [`OutputPaths::check`] does for a run.
pub fn check_ablations_output(dir: &Path) -> Result<()> {
    check_writable(dir)?;
    check_writable(&dir.join("figures"))
}

/// Removes the files with extension `extension` directly in `dir` (outputs of an earlier run that
/// this run might not write again, e.g. a condition that was removed).
fn remove_stale(dir: &Path, extensions: &[&str]) -> Result<()> {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return Ok(());
    };
    for entry in entries.flatten() {
        let path = entry.path();
        let stale = path
            .extension()
            .and_then(|e| e.to_str())
            .is_some_and(|e| extensions.contains(&e));
        if stale && path.is_file() {
            std::fs::remove_file(&path).map_err(|source| PipelineError::Io {
                path: path.clone(),
                source,
            })?;
        }
    }
    Ok(())
}

/// Writes every output of `outcome` and returns the files written. `write_seconds` is the time
/// this takes, recorded in `timings.json` with the run's stages.
pub fn write_outputs(outcome: &RunOutcome, paths: &OutputPaths) -> Result<Vec<PathBuf>> {
    let start = std::time::Instant::now();
    let mut written = Vec::new();
    remove_stale(&paths.tables_dir(), &["json", "md"])?;
    remove_stale(&paths.figures_dir(), &["svg"])?;
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
    write_text(&summary, &to_json(&outcome.summary))?;
    written.push(summary);
    if let Some(readme) = &paths.readme {
        update_readme(readme, &readme_block(outcome, paths, readme))?;
        written.push(readme.clone());
    }
    let mut stages = outcome.timings.clone();
    stages.push(StageTiming {
        stage: "write outputs".to_string(),
        seconds: start.elapsed().as_secs_f64(),
    });
    let timings = Timings {
        run: outcome.summary.run.clone(),
        uncommitted_inputs: outcome.uncommitted_inputs,
        threads: rayon::current_num_threads(),
        total_seconds: stages.iter().map(|s| s.seconds).sum(),
        stages,
    };
    let timings_path = paths.results_dir.join("timings.json");
    write_text(&timings_path, &to_json(&timings))?;
    written.push(timings_path);
    Ok(written)
}

fn to_json<T: serde::Serialize>(value: &T) -> String {
    let mut text = serde_json::to_string_pretty(value).expect("outputs serialise");
    text.push('\n');
    text
}

/// The README's generated block: every table, then a pointer to the figures.
fn readme_block(outcome: &RunOutcome, paths: &OutputPaths, readme: &Path) -> String {
    let mut block = String::new();
    for table in &outcome.tables {
        block.push_str(&markdown(table));
        block.push('\n');
    }
    let base = readme.parent().unwrap_or(Path::new(""));
    let figures = paths.figures_dir();
    let relative = figures.strip_prefix(base).unwrap_or(&figures);
    if let Some((name, _)) = outcome
        .figures
        .iter()
        .find(|(name, _)| name.starts_with("full_"))
    {
        block.push_str(&format!(
            "The paper's qualitative figure, one per table and condition, is in `{}/`; for \
             example the full dynamics in the first condition:\n\n![{name}]({}/{name})\n",
            relative.display(),
            relative.display()
        ));
    }
    block
}

fn read_readme(readme: &Path) -> Result<String> {
    std::fs::read_to_string(readme).map_err(|source| PipelineError::Io {
        path: readme.to_path_buf(),
        source,
    })
}

/// The byte range of the generated block in a README's `text`: from the end of [`README_BEGIN`]
/// to the start of [`README_END`].
fn results_block(readme: &Path, text: &str) -> Result<std::ops::Range<usize>> {
    let missing = || PipelineError::Config {
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
    let std::ops::Range {
        start: after_begin,
        end,
    } = results_block(readme, &text)?;
    let updated = format!(
        "{}\n\n{}\n{}",
        &text[..after_begin],
        block.trim_end(),
        &text[end..]
    );
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
    #[cfg(unix)]
    fn an_input_linked_into_a_replaced_directory_is_an_output() {
        let dir = std::env::temp_dir().join(format!("pipeline-linked-{}", std::process::id()));
        std::fs::create_dir_all(dir.join("res/tables")).unwrap();
        std::fs::write(dir.join("res/tables/r.json"), "{}").unwrap();
        std::os::unix::fs::symlink(dir.join("res/tables/r.json"), dir.join("c.json")).unwrap();
        let paths = OutputPaths {
            results_dir: dir.join("res"),
            latex_dir: dir.join("tex"),
            readme: None,
        };
        let same = |a: &Path, b: &Path| match (a.canonicalize(), b.canonicalize()) {
            (Ok(a), Ok(b)) => a == b,
            _ => false,
        };
        let clobbers = paths
            .planned(&["translational"])
            .clobbers(&dir.join("c.json"), &same);
        std::fs::remove_dir_all(&dir).unwrap();
        assert!(clobbers.unwrap().starts_with("every *.json in "));
    }

    #[test]
    fn planned_outputs_name_the_files_written_and_the_directories_replaced() {
        let paths = OutputPaths {
            results_dir: PathBuf::from("res"),
            latex_dir: PathBuf::from("tex"),
            readme: None,
        };
        let planned = paths.planned(&["translational"]);
        let same = |a: &Path, b: &Path| a == b;
        let clobbers = |path: &str| planned.clobbers(Path::new(path), &same);
        assert_eq!(clobbers("res/summary.json").unwrap(), "res/summary.json");
        assert_eq!(
            clobbers("tex/translational.tex").unwrap(),
            "tex/translational.tex"
        );
        assert_eq!(
            clobbers("res/tables/mine.json").unwrap(),
            "every *.json in res/tables (replaced)"
        );
        assert!(clobbers("res/figures/a.svg").is_some());
        for untouched in [
            "res/tables/mine.csv",
            "res/other.json",
            "tex/attitude.tex",
            "x.json",
        ] {
            assert_eq!(clobbers(untouched), None, "{untouched}");
        }
        let ablations = planned_ablations(Path::new("out"));
        assert!(
            ablations
                .clobbers(Path::new("out/ablations.json"), &same)
                .is_some()
        );
        assert!(
            ablations
                .clobbers(Path::new("out/variants.json"), &same)
                .is_none()
        );
    }

    #[test]
    fn readme_block_is_replaced_and_the_rest_kept() {
        let dir = std::env::temp_dir().join(format!("pipeline-readme-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let readme = dir.join("README.md");
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
        // The same is found before a run, and so is an output directory that cannot be made.
        let paths = |results_dir: PathBuf| OutputPaths {
            results_dir,
            latex_dir: dir.join("latex"),
            readme: Some(readme.clone()),
        };
        let message = paths(dir.join("results")).check().unwrap_err().to_string();
        assert!(message.contains("tables:begin"), "{message}");
        std::fs::write(&readme, &original).unwrap();
        paths(dir.join("results")).check().unwrap();
        assert!(dir.join("latex").is_dir() && !dir.join("results/.learn-write-check").exists());
        let message = paths(readme.join("results"))
            .check()
            .unwrap_err()
            .to_string();
        assert!(message.contains("README.md/results"), "{message}");
    }

    #[test]
    fn the_ablations_output_is_checked_before_any_work() {
        let dir =
            std::env::temp_dir().join(format!("pipeline-ablations-out-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        check_ablations_output(&dir.join("out")).unwrap();
        assert!(dir.join("out/figures").is_dir());
        assert!(!dir.join("out/.learn-write-check").exists());
        // A file where the directory should be.
        let file = dir.join("a-file");
        std::fs::write(&file, "").unwrap();
        let message = check_ablations_output(&file).unwrap_err().to_string();
        assert!(message.contains("a-file"), "{message}");
        // A directory where `figures/` cannot be made.
        std::fs::create_dir_all(dir.join("blocked")).unwrap();
        std::fs::write(dir.join("blocked/figures"), "").unwrap();
        let message = check_ablations_output(&dir.join("blocked"))
            .unwrap_err()
            .to_string();
        assert!(message.contains("blocked/figures"), "{message}");
        assert!(!message.contains('\n'), "{message}");
    }
}
