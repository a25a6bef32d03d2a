//! The committed demo summary (`results/mismatch/summary.{json,md}`): read back from its JSON, the
//! summary renders the committed Markdown byte for byte and serialises to the committed JSON.

use std::path::{Path, PathBuf};

use serde::de::DeserializeOwned;
use serde_json::Value;

use super::CellOutcome;
use super::summary::{ConfigurationSummary, DemoSummary, ParameterCheck, Targets};

fn committed(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../results/mismatch")
        .join(name)
}

fn read(name: &str) -> String {
    std::fs::read_to_string(committed(name)).unwrap()
}

fn from<T: DeserializeOwned>(value: &Value) -> T {
    serde_json::from_value(value.clone()).unwrap()
}

fn configuration(c: &Value) -> ConfigurationSummary {
    ConfigurationSummary {
        name: from(&c["name"]),
        description: from(&c["description"]),
        vehicle: from(&c["vehicle"]),
        controller_rate_hz: from(&c["controller_rate_hz"]),
        log_rate_hz: from(&c["log_rate_hz"]),
        logger: from(&c["logger"]),
        jitter: from(&c["jitter"]),
        noise: from(&c["noise"]),
        trajectory: from(&c["trajectory"]),
    }
}

fn cell(c: &Value) -> CellOutcome {
    let parameters = c["parameters"].as_array().unwrap();
    CellOutcome {
        configuration: from(&c["configuration"]),
        case: from(&c["case"]),
        seed: from(&c["seed"]),
        true_effects: from(&c["true_effects"]),
        found_effects: from(&c["found_effects"]),
        named_exactly: from(&c["named_exactly"]),
        parameters: parameters
            .iter()
            .map(|p| ParameterCheck {
                effect: from(&p["effect"]),
                parameter: from(&p["parameter"]),
                truth: from(&p["truth"]),
                found: from(&p["found"]),
                standard_error: from(&p["standard_error"]),
                within_two_standard_errors: from(&p["within_two_standard_errors"]),
                standard_errors_off: from(&p["standard_errors_off"]),
                relative_error: from(&p["relative_error"]),
                chance_within_target: from(&p["chance_within_target"]),
            })
            .collect(),
        heldout_mse_before: from(&c["heldout_mse_before"]),
        heldout_mse_after: from(&c["heldout_mse_after"]),
        heldout_ratio: from(&c["heldout_ratio"]),
        heldout_target: from(&c["heldout_target"]),
        passed: from(&c["passed"]),
        failures: from(&c["failures"]),
        unexplained: from(&c["unexplained"]),
    }
}

/// The summary as the committed JSON records it (the cells as judged then: not judged again).
fn committed_summary() -> DemoSummary {
    committed_summary_of("summary.json")
}

/// [`committed_summary`] of the JSON file `name` in `results/mismatch`.
fn committed_summary_of(name: &str) -> DemoSummary {
    let json: Value = serde_json::from_str(&read(name)).unwrap();
    let targets = &json["targets"];
    DemoSummary {
        targets: Targets {
            parameters_within: from(&targets["parameters_within"]),
            heldout_ratio_at_most: from(&targets["heldout_ratio_at_most"]),
            heldout_noise_multiple_at_most: from(&targets["heldout_noise_multiple_at_most"]),
        },
        configurations: json["configurations"]
            .as_array()
            .unwrap()
            .iter()
            .map(configuration)
            .collect(),
        cases: from(&json["cases"]),
        cells: json["cells"].as_array().unwrap().iter().map(cell).collect(),
    }
}

/// The timing matrix (`make mismatch-demo`'s second run) renders its Markdown as committed.
#[test]
fn the_committed_timing_summary_renders_its_committed_markdown() {
    let summary = committed_summary_of("timing/summary.json");
    let manifest = Path::new("experiments/mismatch/demo-timing.json");
    assert_eq!(summary.view(manifest).markdown(), read("timing/summary.md"));
}

/// The '+' quadrotor's matrix (`make mismatch-demo`'s third run) renders its Markdown as committed.
#[test]
fn the_committed_vehicles_summary_renders_its_committed_markdown() {
    let summary = committed_summary_of("vehicles/summary.json");
    let manifest = Path::new("experiments/mismatch/demo-vehicles.json");
    assert_eq!(
        summary.view(manifest).markdown(),
        read("vehicles/summary.md")
    );
}

#[test]
fn the_committed_summary_renders_its_committed_markdown() {
    let summary = committed_summary();
    assert_eq!(
        summary
            .view(Path::new("experiments/mismatch/demo.json"))
            .markdown(),
        read("summary.md")
    );
}

#[test]
fn the_committed_summary_is_read_back_whole() {
    let summary = committed_summary();
    let text = serde_json::to_string_pretty(&summary).unwrap() + "\n";
    let again: Value = serde_json::from_str(&text).unwrap();
    let committed: Value = serde_json::from_str(&read("summary.json")).unwrap();
    assert_eq!(again, committed);
}

#[test]
fn the_committed_summary_prints_one_line_per_cell_and_the_total() {
    let text = committed_summary()
        .view(Path::new("experiments/mismatch/demo.json"))
        .table_text();
    let lines: Vec<&str> = text.lines().collect();
    assert_eq!(lines.len(), 185);
    assert_eq!(
        lines[0],
        "A          control                            OK   found [] held-out MSE ×1.000"
    );
    assert_eq!(
        lines[8],
        "A          inertia_scale                      OK   found [inertia_scale] held-out MSE ×0.083"
    );
    assert_eq!(
        lines[17],
        "A          linear_drag+inertia_scale          OK   found [linear_drag, inertia_scale] held-out MSE ×0.066"
    );
    assert_eq!(lines[184], "184 of 184 cells meet every target");
}

#[test]
fn a_cell_that_misses_prints_why_and_counts_against_the_total() {
    let mut summary = committed_summary();
    let cell = &mut summary.cells[17];
    cell.passed = false;
    cell.failures = vec!["inertia_scale.k off by 11% (2.3 standard errors)".to_string()];
    let text = summary
        .view(Path::new("experiments/mismatch/demo.json"))
        .table_text();
    let lines: Vec<&str> = text.lines().collect();
    assert_eq!(
        lines[17],
        "A          linear_drag+inertia_scale          MISS found [linear_drag, inertia_scale] held-out MSE ×0.066 (inertia_scale.k off by 11% (2.3 standard errors))"
    );
    assert_eq!(lines[184], "183 of 184 cells meet every target");
}
