//! A new wind condition is data plus one entry in the conditions file: it becomes a new row of
//! every table and a new figure per table, with no code change. Uses the real flights (one copied
//! under a temporary data directory as the new condition) and a tiny LeARN budget.

use std::path::{Path, PathBuf};

use std::sync::Mutex;
use std::sync::atomic::{AtomicUsize, Ordering};

use evaluation::{OutputPaths, Progress, RunConfig, Stage, StageTiming, run, write_outputs};
use serde_json::{Value, json};

fn workspace() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// The real data directory (see `data::real_data_dir_for_tests`: skips locally, fails under CI).
fn real_data_dir() -> Option<PathBuf> {
    data::real_data_dir_for_tests(&Path::new(env!("CARGO_MANIFEST_DIR")).join("../.."))
}

/// A fresh temporary directory, removed with everything in it when dropped (a symbolic link in it
/// is removed, not followed).
fn temp_dir(name: &str) -> tempfile::TempDir {
    tempfile::Builder::new()
        .prefix(&format!("evaluation-{name}-"))
        .tempdir()
        .unwrap()
}

/// A data directory whose `experiment/` is the real one and whose `extra/` holds a copy of the
/// baseline 35wind flight under a new name.
fn data_dir_with_new_flight(real: &Path, dir: &Path) -> PathBuf {
    let data = dir.join("data");
    std::fs::create_dir_all(data.join("extra")).unwrap();
    std::os::unix::fs::symlink(
        std::fs::canonicalize(real.join("experiment")).unwrap(),
        data.join("experiment"),
    )
    .unwrap();
    std::fs::copy(
        real.join("experiment/custom_figure8_baseline_35wind.csv"),
        data.join("extra/custom_figure8_baseline_gust.csv"),
    )
    .unwrap();
    data
}

/// A small conditions file (two controllers, one meta-training and one evaluation condition),
/// optionally with the new condition.
fn conditions(with_new: bool) -> Value {
    let real: Value = serde_json::from_str(
        &std::fs::read_to_string(workspace().join("experiments/conditions.json")).unwrap(),
    )
    .unwrap();
    let mut entries = vec![
        json!({"name": "nowind", "wind_speed": "0 m/s", "role": "meta-training"}),
        json!({"name": "35wind", "wind_speed": "4.2 m/s", "role": "evaluation"}),
    ];
    if with_new {
        entries.push(json!({
            "name": "gust", "wind_speed": "4.2 m/s (a copy of 35wind)", "role": "evaluation",
            "files": {"baseline": "extra/custom_figure8_baseline_gust.csv"}
        }));
    }
    json!({
        "file_pattern": real["file_pattern"],
        "controllers": ["baseline", "NF"],
        "evaluation_controller": "baseline",
        "conditions": entries,
        "paper_training": real["paper_training"],
    })
}

/// An observer that counts the units of work and records the stages.
#[derive(Default)]
struct Counting {
    /// (name, units announced) of each stage, as it starts.
    started: Mutex<Vec<(String, Option<usize>)>>,
    advances: AtomicUsize,
    finished: Mutex<Vec<String>>,
}

impl Progress for Counting {
    fn stage(&self, stage: &Stage<'_>) {
        let units = stage.units.map(|units| units.total);
        self.started
            .lock()
            .unwrap()
            .push((stage.name.to_string(), units));
    }

    fn advance(&self, unit: std::fmt::Arguments<'_>) {
        assert!(unit.to_string().contains(" seed 7"), "{unit}");
        self.advances.fetch_add(1, Ordering::Relaxed);
    }

    fn finish(&self, timing: &StageTiming) {
        self.finished.lock().unwrap().push(timing.stage.clone());
    }
}

/// Runs the evaluation on `conditions` with a tiny LeARN budget and writes under `out`; its observer
/// sees every stage, and every LeARN cell (three tables × the evaluation conditions) once.
fn run_with(dir: &Path, data: &Path, conditions: &Value, out: &Path) {
    let conditions_path = dir.join(format!(
        "conditions-{}.json",
        conditions["conditions"].as_array().unwrap().len()
    ));
    std::fs::write(&conditions_path, conditions.to_string()).unwrap();
    let root = workspace();
    let config = json!({
        "name": "extending-test",
        "description": "tiny budget",
        "formulations": ["translational", "attitude", "full"],
        "conditions": conditions_path,
        "published": root.join("paper/published.json"),
        "split": {"kind": "halves"},
        "derivative": {"kind": "forward"},
        "sindy": {"library": {"kind": "fourier", "frequencies": 1},
                  "optimizer": {"kind": "stlsq", "threshold": 0.2}},
        "learn": {
            "config": root.join("experiments/learn.json"),
            "overrides": {
                "meta_training": {"iterations": 2, "task_batch": 2,
                                  "support_batch": 16, "query_batch": 16},
                "adaptation": {"passes": 1}
            },
            "seeds": [7]
        }
    });
    let config_path = dir.join("run.json");
    std::fs::write(&config_path, config.to_string()).unwrap();
    let checked = RunConfig::load(&config_path, &root).unwrap();
    let observer = Counting::default();
    let outcome = run(&checked, data, &root, &observer).unwrap();
    let cells = 3 * conditions["conditions"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|c| c["role"] == "evaluation")
        .count();
    assert_eq!(observer.advances.load(Ordering::Relaxed), cells);
    let started = observer.started.into_inner().unwrap();
    let finished = observer.finished.into_inner().unwrap();
    let timed: Vec<&str> = outcome.timings.iter().map(|t| t.stage.as_str()).collect();
    assert_eq!(finished, timed);
    assert_eq!(
        started
            .iter()
            .map(|(name, _)| name.as_str())
            .collect::<Vec<_>>(),
        timed
    );
    let counted: Vec<usize> = started.iter().filter_map(|(_, units)| *units).collect();
    assert_eq!(counted, [cells], "{started:?}");
    let paths = OutputPaths {
        results_dir: out.to_path_buf(),
        latex_dir: out.join("latex"),
    };
    write_outputs(&outcome, &paths).unwrap();
}

fn read_json(path: &Path) -> Value {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

fn conditions_of(table: &Value) -> Vec<String> {
    table["rows"]
        .as_array()
        .unwrap()
        .iter()
        .map(|row| row["condition"].as_str().unwrap().to_string())
        .collect()
}

#[test]
fn a_new_condition_is_a_new_row_of_every_table_and_a_new_figure() {
    let Some(real) = real_data_dir() else { return };
    let tmp = temp_dir("extending");
    let dir = tmp.path().to_path_buf();
    let data = data_dir_with_new_flight(&real, &dir);
    run_with(&dir, &data, &conditions(false), &dir.join("before"));
    run_with(&dir, &data, &conditions(true), &dir.join("after"));

    for table in ["translational", "attitude", "full"] {
        let before = read_json(&dir.join(format!("before/tables/{table}.json")));
        let after = read_json(&dir.join(format!("after/tables/{table}.json")));
        assert_eq!(conditions_of(&before), vec!["35wind"]);
        assert_eq!(conditions_of(&after), vec!["35wind", "gust"]);
        let rows = after["rows"].as_array().unwrap();
        // The paper has 35wind, not the new condition.
        assert!(rows[0].get("published").is_some());
        assert!(rows[1].get("published").is_none());
        // The new flight is a copy of 35wind: SINDy, fitted without randomness, agrees exactly.
        assert_eq!(rows[0]["sindy"], rows[1]["sindy"]);
        // LeARN numbers exist and are errors.
        for metric in ["adapt", "gen"] {
            let value = rows[1]["learn"][metric].as_f64().unwrap();
            assert!(
                value.is_finite() && value > 0.0,
                "{table} {metric}: {value}"
            );
        }
        let markdown =
            std::fs::read_to_string(dir.join(format!("after/tables/{table}.md"))).unwrap();
        assert!(
            markdown.lines().any(|l| l.starts_with("| gust |")),
            "{markdown}"
        );
        let latex = std::fs::read_to_string(dir.join(format!("after/latex/{table}.tex"))).unwrap();
        assert!(latex.lines().any(|l| l.starts_with("gust ")), "{latex}");
        assert!(
            !dir.join(format!("before/figures/{table}_gust.svg"))
                .exists()
        );
        let figure =
            std::fs::read_to_string(dir.join(format!("after/figures/{table}_gust.svg"))).unwrap();
        assert!(figure.contains("SINDy (gust)") && figure.contains("LeARN (gust)"));
    }
    let summary = read_json(&dir.join("after/summary.json"));
    let new_cells: Vec<&Value> = summary["cells"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|c| c["condition"] == "gust")
        .collect();
    assert_eq!(new_cells.len(), 3);
    assert_eq!(
        new_cells[0]["flight"]["path"],
        "extra/custom_figure8_baseline_gust.csv"
    );
    assert_eq!(
        summary["provenance"]["protocol"], "leave-condition-out",
        "no paper training flights in the temporary data directory"
    );

    // The same inputs give byte-identical outputs (wall times live in timings.json).
    run_with(&dir, &data, &conditions(true), &dir.join("again"));
    let mut compared = 0;
    for relative in [
        "summary.json",
        "tables/full.json",
        "tables/attitude.md",
        "latex/translational.tex",
        "figures/full_gust.svg",
        "figures/attitude_35wind.svg",
    ] {
        let first = std::fs::read(dir.join("after").join(relative)).unwrap();
        let second = std::fs::read(dir.join("again").join(relative)).unwrap();
        assert!(
            first == second,
            "{relative} differs between two identical runs"
        );
        compared += 1;
    }
    assert_eq!(compared, 6);
}
