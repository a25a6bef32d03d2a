//! `learn sindy` beyond one file: several recordings fitted as trajectories, uneven time steps on
//! their true time stamps, and a saved model read back to predict and simulate on new data.

mod common;

use std::path::Path;

use common::{learn_in, scratch};

/// `t,x,y,u` of the damped rotation ẋ = −0.1 x + y, ẏ = −x − 0.1 y from t = `start`, at the
/// times `start + step·k` moved by up to ±`jitter` of a step.
fn rotation(start: f64, rows: usize, step: f64, jitter: f64) -> String {
    let mut text = String::from("t,x,y,u\n");
    for k in 0..rows {
        let wobble = ((k * 7919) % 1000) as f64 / 500.0 - 1.0;
        let t = start + step * (k as f64 + if k == 0 { 0.0 } else { jitter * wobble });
        let decay = (-0.1 * t).exp();
        let (x, y) = (decay * t.cos(), -decay * t.sin());
        text.push_str(&format!("{t},{x},{y},{}\n", (0.5 * t).sin()));
    }
    text
}

fn fit(dir: &Path, files: &[&str], extra: &[&str]) -> common::Run {
    let mut args = vec!["sindy"];
    for file in files {
        args.extend(["--csv", file]);
    }
    args.extend(["--state", "x,y", "--control", "u", "--library", "poly:1"]);
    args.extend(["--threshold", "0.01"]);
    args.extend_from_slice(extra);
    learn_in(dir, &args)
}

#[test]
fn several_files_are_fitted_as_trajectories() {
    let dir = scratch("sindy-trajectories");
    std::fs::write(dir.join("a.csv"), rotation(0.0, 300, 0.01, 0.0)).unwrap();
    std::fs::write(dir.join("b.csv"), rotation(7.0, 300, 0.01, 0.0)).unwrap();
    let run = fit(&dir, &["a.csv", "b.csv"], &[]);
    let equations = run.success();
    assert!(equations.contains("x' = -0.100 x + 1.000 y"), "{equations}");
    assert!(equations.contains("y' = -1.000 x - 0.100 y"), "{equations}");
    assert!(
        run.stderr.contains("600 samples in 2 trajectories"),
        "{}",
        run.stderr
    );
    fit(&dir, &["a.csv", "b.csv"], &["--stream"]).one_line_error(&["--stream reads one --csv"]);
}

#[test]
fn uneven_time_steps_use_the_true_time_stamps_and_savgol_refuses_them() {
    let dir = scratch("sindy-uneven");
    std::fs::write(dir.join("jitter.csv"), rotation(0.0, 600, 0.01, 0.3)).unwrap();
    let run = fit(&dir, &["jitter.csv"], &["--derivative", "central"]);
    let equations = run.success();
    assert!(equations.contains("x' = -0.100 x + 1.000 y"), "{equations}");
    // Read in blocks, the same fit on the same time stamps.
    let streamed = fit(
        &dir,
        &["jitter.csv"],
        &["--derivative", "central", "--stream"],
    );
    assert_eq!(streamed.success(), equations);
    let run = fit(&dir, &["jitter.csv"], &["--derivative", "savgol:7:2"]);
    run.one_line_error(&["jitter.csv:3:t", "needs uniform samples"]);
    let run = fit(
        &dir,
        &["jitter.csv"],
        &["--derivative", "savgol:7:2", "--stream"],
    );
    run.one_line_error(&["jitter.csv:", "savgol:7:2 derivative needs even time steps"]);
}

#[test]
fn a_saved_model_predicts_and_simulates_new_data() {
    let dir = scratch("sindy-apply");
    std::fs::write(dir.join("train.csv"), rotation(0.0, 400, 0.01, 0.0)).unwrap();
    std::fs::write(dir.join("new.csv"), rotation(3.0, 500, 0.02, 0.2)).unwrap();
    fit(&dir, &["train.csv"], &["--out", "model.json"]).success();

    let apply = |command: &str, out: &str| {
        let args = [
            "sindy",
            command,
            "--model",
            "model.json",
            "--csv",
            "new.csv",
            "--out",
            out,
        ];
        learn_in(&dir, &args)
    };
    let run = apply("predict", "xdot.csv");
    let line = run.success();
    assert!(line.contains("new.csv: 500 samples; MSE of ẋ"), "{line}");
    let r2: f64 = line.rsplit("R² ").next().unwrap().trim().parse().unwrap();
    assert!(r2 > 0.999, "{line}");
    let written = std::fs::read_to_string(dir.join("xdot.csv")).unwrap();
    assert!(written.starts_with("t,x',y'\n"), "{written}");
    assert_eq!(written.lines().count(), 501);

    let run = apply("simulate", "sim.csv");
    let line = run.success();
    // "…: x 0.000012, y 0.000034": the largest RMSE.
    let worst = line
        .rsplit(": ")
        .next()
        .unwrap()
        .split(", ")
        .filter_map(|part| part.split(' ').nth(1)?.trim().parse::<f64>().ok())
        .fold(f64::NAN, f64::max);
    assert!(worst < 1e-3, "{line}");
    let written = std::fs::read_to_string(dir.join("sim.csv")).unwrap();
    assert!(written.starts_with("t,x,y\n"), "{written}");
    // The output is never replaced without --force; a recording without the model's columns is
    // named.
    apply("simulate", "sim.csv").one_line_error(&["sim.csv"]);
    std::fs::write(dir.join("other.csv"), "t,x,z,u\n0,1,2,3\n0.1,1,2,3\n").unwrap();
    learn_in(
        &dir,
        &[
            "sindy",
            "predict",
            "--model",
            "model.json",
            "--csv",
            "other.csv",
        ],
    )
    .one_line_error(&["other.csv", "y"]);
}
