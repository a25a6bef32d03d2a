//! The workspace's layering (issues 19 and 32), read from the dependency graph `cargo metadata`
//! resolves: for each crate the full closure of what it depends on (normal and build
//! dependencies, through every crate on the way, not dev-dependencies), checked against what it
//! must never pull in. `sindy` and `learn` are libraries on in-memory data (no flight-log crate,
//! CSV reader, data-frame library or file hash); `data` reads files and computes nothing (no
//! `sindy`, no linear algebra, no output sets); `evaluation` draws no progress bar (the `learn`
//! binary does); `mismatch` returns results and file contents (the binary checks and writes
//! them); `report` depends on no crate that computes results, however indirectly (data flows
//! cli → evaluation / mismatch → report); the Python package `python` reuses the libraries, not
//! the command line's crates.

use std::collections::{BTreeMap, BTreeSet};
use std::path::Path;
use std::sync::OnceLock;

use serde_json::Value;

/// Every package of the workspace's resolved graph, by name: the names of the packages it depends
/// on as a library (normal or build dependencies; dev-dependencies are the tests' own).
fn graph() -> &'static BTreeMap<String, BTreeSet<String>> {
    static GRAPH: OnceLock<BTreeMap<String, BTreeSet<String>>> = OnceLock::new();
    GRAPH.get_or_init(|| {
        let manifest = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../Cargo.toml");
        let cargo = std::env::var_os("CARGO").unwrap_or_else(|| "cargo".into());
        let output = std::process::Command::new(cargo)
            .args(["metadata", "--format-version", "1", "--manifest-path"])
            .arg(&manifest)
            .output()
            .expect("cargo metadata runs");
        assert!(
            output.status.success(),
            "cargo metadata: {}",
            String::from_utf8_lossy(&output.stderr)
        );
        let metadata: Value = serde_json::from_slice(&output.stdout).expect("metadata is JSON");
        let name_of: BTreeMap<&str, &str> = metadata["packages"]
            .as_array()
            .expect("packages")
            .iter()
            .map(|p| (p["id"].as_str().unwrap(), p["name"].as_str().unwrap()))
            .collect();
        let mut graph = BTreeMap::<String, BTreeSet<String>>::new();
        for node in metadata["resolve"]["nodes"].as_array().expect("resolve") {
            let dependencies = node["deps"]
                .as_array()
                .expect("deps")
                .iter()
                .filter(|d| {
                    d["dep_kinds"]
                        .as_array()
                        .expect("dep_kinds")
                        .iter()
                        .any(|k| k["kind"].as_str() != Some("dev"))
                })
                .map(|d| name_of[d["pkg"].as_str().unwrap()].to_string());
            graph
                .entry(name_of[node["id"].as_str().unwrap()].to_string())
                .or_default()
                .extend(dependencies);
        }
        graph
    })
}

/// The packages `name` depends on directly.
fn direct(name: &str) -> &'static BTreeSet<String> {
    graph()
        .get(name)
        .unwrap_or_else(|| panic!("{name} is not in the workspace's graph"))
}

/// Every package `name` depends on, directly or through others, each with the path that pulls it
/// in (`name → a → b`).
fn closure(name: &str) -> BTreeMap<String, String> {
    let mut reached = BTreeMap::new();
    let mut frontier = vec![(name.to_string(), name.to_string())];
    while let Some((package, path)) = frontier.pop() {
        for dependency in direct(&package) {
            if !reached.contains_key(dependency) {
                let through = format!("{path} → {dependency}");
                reached.insert(dependency.clone(), through.clone());
                frontier.push((dependency.clone(), through));
            }
        }
    }
    reached
}

/// Asserts that `name` depends directly on every one of `required` and, however indirectly, on
/// none of `forbidden` (the message names the path that pulls one in).
fn assert_layered(name: &str, required: &[&str], forbidden: &[&str]) {
    let direct = direct(name);
    for needed in required {
        assert!(
            direct.contains(*needed),
            "{name} needs {needed}: {direct:?}"
        );
    }
    let reached = closure(name);
    let pulled: Vec<&String> = forbidden.iter().filter_map(|f| reached.get(*f)).collect();
    assert!(pulled.is_empty(), "{name} depends on: {pulled:?}");
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
fn data_reads_files_and_computes_nothing() {
    let forbidden = ["sindy", "learn", "faer", "clarabel", "output_set", "report"];
    assert_layered("data", &["bounded_read"], &forbidden);
}

#[test]
fn the_ulog_reader_depends_only_on_the_bounded_reads() {
    let direct = direct("ulog");
    let expected: std::collections::BTreeSet<String> = ["bounded_read", "thiserror"]
        .iter()
        .map(|name| name.to_string())
        .collect();
    assert_eq!(direct, &expected, "ulog depends on {direct:?}");
    assert!(closure("data").contains_key("ulog"));
}

#[test]
fn the_rotation_maths_depends_on_nothing() {
    let direct = direct("rotation");
    assert!(direct.is_empty(), "rotation depends on {direct:?}");
    // Its users share it, and no second copy of the maths lives in them.
    for user in ["data", "physics"] {
        assert!(closure(user).contains_key("rotation"), "{user}");
    }
}

#[test]
fn mismatch_returns_results_and_writes_no_output_set() {
    assert_layered("mismatch", &["report"], &["output_set", "indicatif"]);
}

#[test]
fn the_python_package_reuses_the_libraries_not_the_command_line() {
    let forbidden = ["cli", "clap", "indicatif", "anyhow"];
    assert_layered(
        "python",
        &["sindy", "learn", "mismatch", "pyo3"],
        &forbidden,
    );
    // Output sets (whose staging installs an interrupt handler) are the binary's: the extension
    // writes through Python, and `output_set` reaches it only inside `evaluation`.
    assert!(!direct("python").contains("output_set"));
    // A shell like the `learn` binary: no crate of the workspace depends on it.
    for (package, dependencies) in graph() {
        assert!(
            !dependencies.contains("python"),
            "{package} depends on python"
        );
    }
}

#[test]
fn the_evaluation_crate_draws_no_progress_bar() {
    assert_layered("evaluation", &["report"], &["indicatif"]);
}

#[test]
fn report_depends_on_no_crate_that_computes() {
    let forbidden = [
        "evaluation",
        "learn",
        "sindy",
        "physics",
        "mismatch",
        "data",
        "ulog",
        "faer",
        "clarabel",
        "polars",
        "rayon",
        "indicatif",
    ];
    assert_layered("report", &["plotters"], &forbidden);
    // What it may use at all: the plotting library, serialisation, its error type and the
    // bounded JSON reads.
    let allowed = [
        "plotters",
        "serde",
        "serde_json",
        "thiserror",
        "bounded_read",
    ];
    let direct = direct("report");
    let other: Vec<&String> = direct
        .iter()
        .filter(|d| !allowed.contains(&d.as_str()))
        .collect();
    assert!(other.is_empty(), "report depends on {other:?}");
}

/// The closure is transitive: a crate's dependencies' dependencies count (a check of direct
/// dependencies alone let `report` pull `sindy` through `data`).
#[test]
fn the_closure_follows_every_crate_on_the_way() {
    let mismatch = closure("mismatch");
    assert!(mismatch.contains_key("physics"), "{mismatch:?}");
    // mismatch → report → plotters: two steps, and named with the path.
    assert!(
        mismatch["plotters"].ends_with("report → plotters"),
        "{mismatch:?}"
    );
}
