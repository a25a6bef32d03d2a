//! Nothing a user wrote is replaced without `--force`: each command that writes a file the user
//! names refuses an existing one, before doing any work, and leaves it untouched.

mod common;

use common::{learn_in, scratch};

#[test]
fn seed_spread_refuses_to_replace_an_existing_spread_file() {
    let dir = scratch("seed-spread");
    std::fs::write(dir.join("spread.json"), "{\"mine\": true}\n").unwrap();
    let run = learn_in(
        &dir,
        &["meta-train", "--seed-spread", "--spread-out", "spread.json"],
    );
    run.one_line_error(&["spread.json", "already exists", "--force"]);
    assert_eq!(
        std::fs::read_to_string(dir.join("spread.json")).unwrap(),
        "{\"mine\": true}\n"
    );
}

#[test]
fn seed_spread_covers_every_condition_so_it_rejects_one() {
    let dir = scratch("seed-spread-condition");
    let run = learn_in(
        &dir,
        &["meta-train", "--seed-spread", "--condition", "35wind"],
    );
    run.one_line_usage_error(&["--seed-spread", "--condition", "cannot be used with"]);
}

#[test]
fn sindy_and_simulate_refuse_to_replace_an_existing_output() {
    let dir = scratch("sindy-simulate");
    std::fs::write(dir.join("mine.json"), "mine").unwrap();
    std::fs::write(dir.join("mine.csv"), "mine").unwrap();
    let sindy = learn_in(
        &dir,
        &[
            "sindy",
            "--csv",
            "absent.csv",
            "--state",
            "x",
            "--library",
            "poly:1",
            "--out",
            "mine.json",
        ],
    );
    sindy.one_line_error(&["mine.json", "--force"]);
    let simulate = learn_in(
        &dir,
        &["simulate", "--scenario", "absent.json", "--out", "mine.csv"],
    );
    simulate.one_line_error(&["mine.csv", "--force"]);
    for name in ["mine.json", "mine.csv"] {
        assert_eq!(std::fs::read_to_string(dir.join(name)).unwrap(), "mine");
    }
}

#[test]
fn an_output_is_never_one_of_the_inputs_even_with_force() {
    let dir = scratch("input-as-output");
    let csv = "t,x\n0,1\n0.1,2\n0.2,3\n0.3,4\n0.4,5\n";
    std::fs::write(dir.join("data.csv"), csv).unwrap();
    std::fs::write(dir.join("scenario.json"), "{}").unwrap();
    let sindy = learn_in(
        &dir,
        &[
            "sindy",
            "--csv",
            "data.csv",
            "--state",
            "x",
            "--library",
            "poly:1",
            "--out",
            "./data.csv",
            "--force",
        ],
    );
    sindy.one_line_error(&["data.csv", "is the --csv input"]);
    let simulate = learn_in(
        &dir,
        &[
            "simulate",
            "--scenario",
            "scenario.json",
            "--out",
            "scenario.json",
            "--force",
        ],
    );
    simulate.one_line_error(&["scenario.json", "is the --scenario input"]);
    assert_eq!(std::fs::read_to_string(dir.join("data.csv")).unwrap(), csv);
    assert_eq!(
        std::fs::read_to_string(dir.join("scenario.json")).unwrap(),
        "{}"
    );
}
