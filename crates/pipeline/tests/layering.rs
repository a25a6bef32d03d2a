//! Libraries return typed results, `report` renders them and the `learn` binary owns the progress
//! bars (issue 19): the pipeline draws nothing itself, and `report` depends on no crate that runs
//! the experiments (data flows cli → pipeline → report).

use std::path::Path;

/// The names in the `[dependencies]` table of the workspace crate `name`.
fn dependencies(name: &str) -> Vec<String> {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("..")
        .join(name)
        .join("Cargo.toml");
    let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let mut in_table = false;
    let mut names = Vec::new();
    for line in text.lines().map(str::trim) {
        if line.starts_with('[') {
            in_table = line == "[dependencies]";
        } else if in_table && !line.is_empty() && !line.starts_with('#') {
            let name = line.split(['=', '.', ' ']).next().unwrap_or_default();
            names.push(name.to_string());
        }
    }
    names
}

#[test]
fn the_pipeline_draws_no_progress_bar() {
    let direct = dependencies("pipeline");
    assert!(direct.contains(&"report".to_string()), "{direct:?}");
    assert!(!direct.contains(&"indicatif".to_string()), "{direct:?}");
}

#[test]
fn report_depends_on_no_crate_that_runs_the_experiments() {
    let direct = dependencies("report");
    assert!(direct.contains(&"plotters".to_string()), "{direct:?}");
    for forbidden in ["pipeline", "learn", "sindy", "physics", "indicatif"] {
        assert!(
            !direct.contains(&forbidden.to_string()),
            "report depends on {forbidden}: {direct:?}"
        );
    }
}
