//! The workspace's layering (issue 19), read from the crates' manifests: `sindy` and `learn` are
//! libraries on in-memory data (no flight-log crate, CSV reader, data-frame library or file hash
//! among their dependencies, nor among those of the workspace crates they use); `evaluation` draws
//! no progress bar (the `learn` binary does); `report` depends on no crate that computes results
//! (data flows cli → evaluation / mismatch → report).

use std::path::{Path, PathBuf};

/// The folder of the workspace crate `name`.
fn crate_dir(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..").join(name)
}

/// The names in the `[dependencies]` table of the workspace crate `name`.
fn dependencies(name: &str) -> Vec<String> {
    let path = crate_dir(name).join("Cargo.toml");
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

/// Asserts that `name` (which must depend on every one of `required`) and the workspace crates
/// it depends on directly have none of `forbidden` among their dependencies.
fn assert_layered(name: &str, required: &[&str], forbidden: &[&str]) {
    let direct = dependencies(name);
    for needed in required {
        assert!(direct.iter().any(|d| d == needed), "{name}: {direct:?}");
    }
    let crates = std::iter::once(name.to_string())
        .chain(direct.iter().filter(|d| crate_dir(d).is_dir()).cloned());
    for crate_name in crates {
        for dependency in dependencies(&crate_name) {
            assert!(
                !forbidden.contains(&dependency.as_str()),
                "{crate_name} depends on {dependency}"
            );
        }
    }
}

#[test]
fn sindy_depends_on_no_file_reader_or_data_frame_library() {
    let forbidden = ["data", "polars", "csv", "sha2", "evaluation", "learn"];
    assert_layered("sindy", &["faer"], &forbidden);
}

#[test]
fn learn_depends_on_no_flight_log_csv_reader_or_data_frame_library() {
    let forbidden = [
        "data",
        "polars",
        "csv",
        "sha2",
        "glob",
        "evaluation",
        "report",
    ];
    assert_layered("learn", &["sindy", "faer"], &forbidden);
}

#[test]
fn the_evaluation_crate_draws_no_progress_bar() {
    let direct = dependencies("evaluation");
    assert!(direct.contains(&"report".to_string()), "{direct:?}");
    assert!(!direct.contains(&"indicatif".to_string()), "{direct:?}");
}

#[test]
fn report_depends_on_no_crate_that_runs_the_experiments() {
    let direct = dependencies("report");
    assert!(direct.contains(&"plotters".to_string()), "{direct:?}");
    for forbidden in [
        "evaluation",
        "learn",
        "sindy",
        "physics",
        "mismatch",
        "indicatif",
    ] {
        assert!(
            !direct.contains(&forbidden.to_string()),
            "report depends on {forbidden}: {direct:?}"
        );
    }
}
