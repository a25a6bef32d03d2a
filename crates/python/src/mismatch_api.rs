//! The mismatch analysis of one recording against a nominal model, as `learn mismatch
//! --recording` runs it: the three files' contents are returned, the Python side writes them.

use std::path::{Path, PathBuf};

use pyo3::prelude::*;

use crate::errors::{Progress, raise};

pub fn register(module: &Bound<'_, PyModule>) -> PyResult<()> {
    module.add_function(wrap_pyfunction!(analyze_mismatch, module)?)?;
    Ok(())
}

/// The nominal model: a file read under the project's JSON policy (bounded, no key twice), or
/// JSON text labelled `label` in errors.
fn nominal_model(source: &ModelSource) -> PyResult<physics::NominalModel> {
    let at = |path: &Path, e: &dyn std::fmt::Display| raise(format!("{}: {e}", path.display()));
    match source {
        ModelSource::File(path) => {
            let text = bounded_read::read_json_text(path).map_err(|e| at(path, &e))?;
            let text = bounded_read::json::checked_text(&text).map_err(|e| at(path, &e))?;
            physics::NominalModel::from_json(text, path).map_err(raise)
        }
        ModelSource::Text(text, label) => {
            physics::NominalModel::from_json(text, Path::new(label)).map_err(raise)
        }
    }
}

enum ModelSource {
    File(PathBuf),
    Text(String, String),
}

/// Analyses `recording` (the Neural-Fly layout, or any CSV, Parquet or ULog file with `layout`;
/// only its data rows `rows` when given) against the model in `model_path` or `model_json`; a
/// recording longer than `part_rows` rows is analysed in parts. Returns the contents of
/// `mismatch.json`, `mismatch.svg` and `mismatch.md`, rendered for the folder `out` (named in
/// the Markdown and in errors).
#[pyfunction]
#[pyo3(signature = (recording, out, model_path=None, model_json=None, layout=None, half_width=None, part_rows=None, rows=None, progress=None))]
#[allow(clippy::too_many_arguments)]
fn analyze_mismatch(
    py: Python<'_>,
    recording: PathBuf,
    out: PathBuf,
    model_path: Option<PathBuf>,
    model_json: Option<String>,
    layout: Option<PathBuf>,
    half_width: Option<f64>,
    part_rows: Option<usize>,
    rows: Option<(usize, usize)>,
    progress: Option<Py<PyAny>>,
) -> PyResult<(String, String, String)> {
    let source = match (model_path, model_json) {
        (Some(path), None) => ModelSource::File(path),
        (None, Some(text)) => ModelSource::Text(text, "the model dict".to_string()),
        _ => {
            return Err(raise(
                "give the nominal model as a path or as a dict, not both",
            ));
        }
    };
    let part_rows = part_rows.unwrap_or(mismatch::recording::degenerate::MAX_ANALYSED_ROWS);
    mismatch::check_part_rows(part_rows).map_err(raise)?;
    let mut settings = mismatch::Settings::default();
    if let Some(half_width) = half_width {
        settings.comparison.test_function.half_width_s = half_width;
    }
    let settings = settings.checked().map_err(raise)?;
    let model = nominal_model(&source)?;
    let model_name = match &source {
        ModelSource::File(path) => path.display().to_string(),
        ModelSource::Text(_, label) => label.clone(),
    };
    let progress = Progress::new(progress);
    let files = py.detach(|| -> PyResult<[String; 3]> {
        let rows = rows.map(|(start, end)| start..end);
        let log =
            data::layout::read_recording(&recording, layout.as_deref(), rows).map_err(raise)?;
        if log.len() > part_rows {
            let parts = mismatch::part_ranges(log.len(), part_rows).len();
            let observe = |part: usize, pass: usize, stage: mismatch::Stage| {
                let (part, stage) = (part + 1, stage.describe());
                progress.report((format!("part {part} of {parts}, pass {pass}: {stage}"),));
            };
            let analysis = mismatch::analyze_in_parts(
                &log,
                part_rows,
                &model,
                &model_name,
                &settings,
                &observe,
            )
            .map_err(raise)?;
            return analysis.render(&out).map_err(raise);
        }
        let observe = |pass: usize, stage: mismatch::Stage| {
            progress.report((format!("pass {pass}: {}", stage.describe()),));
        };
        let analysis = mismatch::analyze_observed(&log, &model, &model_name, &settings, &observe)
            .map_err(raise)?;
        analysis.render(&out).map_err(raise)
    });
    let [json, svg, markdown] = progress.finish(files)?;
    Ok((json, svg, markdown))
}
