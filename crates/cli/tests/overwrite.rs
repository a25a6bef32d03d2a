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
    assert_eq!(run.code, Some(2), "{}", run.stderr);
    assert!(run.stderr.contains("cannot be used with"), "{}", run.stderr);
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
