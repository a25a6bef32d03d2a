//! One test per defect class of issue 18 ("data safety"), each asserting the property the README
//! promises, through the built `learn` binary. Each failed on the code before the output sets.

mod common;

use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

use common::{learn_in, scratch};

fn workspace() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../..")
        .canonicalize()
        .unwrap()
}

fn json(path: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

/// A CSV `t,x` of 200 rows with `x` constant at `value`, and one with `x` a sine of amplitude 1.
fn constant_csv(dir: &Path, name: &str, value: &str) -> PathBuf {
    let path = dir.join(name);
    let rows: String = (0..200)
        .map(|i| format!("{},{value}\n", f64::from(i) * 0.01))
        .collect();
    std::fs::write(&path, format!("t,x\n{rows}")).unwrap();
    path
}

fn sine_csv(dir: &Path) -> PathBuf {
    let path = dir.join("sine.csv");
    let rows: String = (0..200)
        .map(|i| {
            let t = f64::from(i) * 0.01;
            format!("{t},{},{}\n", t.sin(), t.cos())
        })
        .collect();
    std::fs::write(&path, format!("t,x,y\n{rows}")).unwrap();
    path
}

/// Class 1: extreme but finite data either fits or is a one-line error about its scale; never a
/// panic, never an equation `x' = 0` beside a false MSE.
#[test]
fn extreme_values_are_a_scale_error_not_a_panic_or_a_false_score() {
    let dir = scratch("hostile-scale");
    for value in ["1e50", "1e154", "1e25", "1e20"] {
        constant_csv(&dir, "c.csv", value);
        let run = learn_in(&dir, &["sindy", "--csv", "c.csv", "--state", "x"]);
        let message = run.one_line_error(&["c.csv", "rescale", "differ in size"]);
        assert!(message.len() < 400, "{message}");
        assert!(run.stdout.is_empty(), "no equations: {}", run.stdout);
    }
    sine_csv(&dir);
    let run = learn_in(
        &dir,
        &[
            "sindy",
            "--csv",
            "sine.csv",
            "--state",
            "x,y",
            "--threshold",
            "0.5",
        ],
    );
    let stdout = run.success();
    assert!(stdout.contains("x' = 1.000 y"), "{stdout}");
}

/// Runs the small ablations (one cheap variant, one seed; `seed` picks the run) into `out` of
/// `dir`, as a child process with piped output.
fn spawn_ablations(dir: &Path, data: &Path, seed: u64, force: bool) -> Child {
    let root = workspace();
    let mut run = json(&root.join("experiments/ci.json"));
    run["formulations"] = serde_json::json!(["translational"]);
    run["learn"]["protocol"] = "leave-condition-out".into();
    for (field, file) in [
        ("/conditions", "experiments/conditions.json"),
        ("/published", "paper/published.json"),
        ("/learn/config", "experiments/learn.json"),
    ] {
        *run.pointer_mut(field).unwrap() = root.join(file).to_str().unwrap().into();
    }
    std::fs::write(dir.join("run.json"), run.to_string()).unwrap();
    let mut variants = json(&root.join("experiments/variants.json"));
    variants["run"] = dir.join("run.json").to_str().unwrap().into();
    variants["seeds"] = serde_json::json!([seed]);
    let kept: Vec<serde_json::Value> = variants["variants"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|v| v["name"] == "lag-ridge-cv")
        .cloned()
        .collect();
    variants["variants"] = kept.into();
    variants["headline"] = "lag-ridge-cv".into();
    variants["reproduce"] = serde_json::json!([]);
    variants.as_object_mut().unwrap().remove("figure_variant");
    std::fs::write(dir.join("tiny.json"), variants.to_string()).unwrap();
    let mut command = Command::new(env!("CARGO_BIN_EXE_learn"));
    command
        .args(["--data", data.to_str().unwrap(), "ablations"])
        .args(["--config", "tiny.json", "--out", "out", "--root"])
        .arg(&root)
        .current_dir(dir)
        .env("RUST_BACKTRACE", "0")
        .stdout(Stdio::null())
        .stderr(Stdio::piped());
    if force {
        command.arg("--force");
    }
    command.spawn().unwrap()
}

/// Waits until a staging folder of a run appears in `out` (the run has checked and locked its
/// outputs and is working), or the child ends: whether the staging was seen.
fn wait_for_staging(out: &Path, child: &mut Child) -> bool {
    let start = Instant::now();
    while start.elapsed() < Duration::from_secs(20) {
        let staging = std::fs::read_dir(out)
            .into_iter()
            .flatten()
            .flatten()
            .any(|e| {
                e.file_name()
                    .to_string_lossy()
                    .starts_with(".learn-staging-")
            });
        if staging {
            return true;
        }
        if child.try_wait().unwrap().is_some() {
            return false;
        }
        std::thread::sleep(Duration::from_millis(1));
    }
    false
}

/// Every file under `dir` with its bytes, by relative path; names starting with `.learn-` are
/// listed apart (`hidden`).
fn snapshot(dir: &Path) -> (Vec<(String, Vec<u8>)>, Vec<String>) {
    let (mut files, mut hidden) = (Vec::new(), Vec::new());
    let mut stack = vec![dir.to_path_buf()];
    while let Some(next) = stack.pop() {
        for entry in std::fs::read_dir(&next).unwrap().flatten() {
            let path = entry.path();
            let name = path.strip_prefix(dir).unwrap().display().to_string();
            let file_name = entry.file_name().to_string_lossy().into_owned();
            if file_name.starts_with(".learn-staging-") || file_name == ".learn-commit.json" {
                hidden.push(name);
            } else if path.is_dir() {
                stack.push(path);
            } else {
                files.push((name, std::fs::read(&path).unwrap()));
            }
        }
    }
    files.sort();
    hidden.sort();
    (files, hidden)
}

fn signal(child: &Child, signal: i32) {
    // SAFETY: sends a signal to our own child process.
    unsafe {
        libc::kill(child.id() as i32, signal);
    }
}

/// Classes 2 and 3: a run killed while it works (SIGKILL or SIGINT) leaves the old result set
/// byte for byte, with nothing that looks like a result (SIGINT: no staging at all; SIGKILL: a
/// hidden staging folder that the next run removes); foreign files in the folder survive every
/// run, and its own earlier files are replaced only with --force.
#[test]
fn interrupted_runs_leave_the_old_set_and_foreign_files_survive() {
    let Some(data) = data::real_data_dir_for_tests(&workspace()) else {
        return;
    };
    let dir = scratch("hostile-kill");
    let out = dir.join("out");
    std::fs::create_dir_all(out.join("figures")).unwrap();
    std::fs::write(out.join("notes.json"), "mine").unwrap();
    std::fs::write(out.join("figures/logo.svg"), "<svg/>").unwrap();
    let old = spawn_ablations(&dir, &data, 2, false)
        .wait_with_output()
        .unwrap();
    assert!(
        old.status.success(),
        "{}",
        String::from_utf8_lossy(&old.stderr)
    );
    let before = snapshot(&out);
    assert!(before.0.iter().any(|(n, _)| n == "ablations.json"));
    assert!(before.1.is_empty(), "{:?}", before.1);

    for (sig, code) in [(libc::SIGINT, Some(130)), (libc::SIGKILL, None)] {
        let mut child = spawn_ablations(&dir, &data, 1, true);
        assert!(
            wait_for_staging(&out, &mut child),
            "the run staged its outputs"
        );
        signal(&child, sig);
        let status = child.wait().unwrap();
        assert_eq!(status.code(), code, "signal {sig}: {status:?}");
        let after = snapshot(&out);
        assert_eq!(
            after.0, before.0,
            "signal {sig}: the old set, byte for byte"
        );
        if sig == libc::SIGINT {
            assert!(
                after.1.is_empty(),
                "SIGINT leaves no staging: {:?}",
                after.1
            );
        }
    }
    // Own files: refused without --force; replaced with it; the SIGKILL's staging removed.
    let again = spawn_ablations(&dir, &data, 1, false)
        .wait_with_output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&again.stderr);
    assert!(
        stderr.contains("--force") && stderr.lines().count() == 1,
        "{stderr}"
    );
    let new = spawn_ablations(&dir, &data, 1, true)
        .wait_with_output()
        .unwrap();
    assert!(
        new.status.success(),
        "{}",
        String::from_utf8_lossy(&new.stderr)
    );
    let after = snapshot(&out);
    assert!(after.1.is_empty(), "{:?}", after.1);
    assert_ne!(after.0, before.0, "the new set replaced the old one");
    for (name, bytes) in [
        ("notes.json", &b"mine"[..]),
        ("figures/logo.svg", b"<svg/>"),
    ] {
        assert_eq!(
            std::fs::read(out.join(name)).unwrap(),
            bytes,
            "{name} survives"
        );
    }
    // A foreign file where the run writes is never replaced, even with --force.
    std::fs::write(
        out.join(".learn-outputs.json"),
        "{\"format\": \"learn-outputs/1\", \"files\": {}}\n",
    )
    .unwrap();
    let foreign = spawn_ablations(&dir, &data, 1, true)
        .wait_with_output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&foreign.stderr);
    assert!(stderr.contains("not written by learn"), "{stderr}");
}

/// Class 3: two runs into one folder never both write: the second is refused while the first
/// holds the folder (frozen here with SIGSTOP while it works), and the first then completes.
/// Class 3 at every moment: SIGINT sent from 0 to 15 ms after the run's staging appears (while
/// it probes its folders, stages, works) leaves no staging name anywhere in the folder. Sent at the
/// first sight of the staging only, an unregistered probe file once survived on a loaded CI
/// machine; the race is too narrow to hit on demand, so `output_set`'s unit test pins that cause.
#[test]
fn an_interrupt_at_any_moment_leaves_no_staging() {
    let Some(data) = data::real_data_dir_for_tests(&workspace()) else {
        return;
    };
    let dir = scratch("hostile-sigint-moments");
    let out = dir.join("out");
    for delay_ms in 0..16u64 {
        let mut child = spawn_ablations(&dir, &data, 1, true);
        if !wait_for_staging(&out, &mut child) {
            let _ = child.wait();
            continue;
        }
        std::thread::sleep(Duration::from_millis(delay_ms));
        signal(&child, libc::SIGINT);
        let status = child.wait().unwrap();
        let hidden = snapshot(&out).1;
        assert!(
            hidden.is_empty(),
            "SIGINT after {delay_ms} ms ({status:?}) left {hidden:?}"
        );
    }
}

#[test]
fn a_second_run_into_a_busy_folder_is_refused() {
    let Some(data) = data::real_data_dir_for_tests(&workspace()) else {
        return;
    };
    let dir = scratch("hostile-concurrent");
    let out = dir.join("out");
    std::fs::create_dir_all(&out).unwrap();
    let mut first = spawn_ablations(&dir, &data, 1, false);
    assert!(wait_for_staging(&out, &mut first), "the first run staged");
    signal(&first, libc::SIGSTOP);
    let second = spawn_ablations(&dir, &data, 2, true)
        .wait_with_output()
        .unwrap();
    signal(&first, libc::SIGCONT);
    let stderr = String::from_utf8_lossy(&second.stderr);
    assert_eq!(second.status.code(), Some(1), "{stderr}");
    assert!(
        stderr.contains("another learn run is writing into this directory"),
        "{stderr}"
    );
    assert!(first.wait().unwrap().success());
    let written = std::fs::read_to_string(out.join("ablations.json")).unwrap();
    assert!(
        written.contains("\"seeds\": [\n      1\n    ]"),
        "the first run's set"
    );
}

/// Class 4: absurd inputs are a quick one-line error within a bounded address space: a header of
/// 200,000 names, `/dev/zero` as a model, a 50 MB field in a configuration.
#[test]
fn absurd_inputs_are_refused_within_bounded_memory() {
    let dir = scratch("hostile-memory");
    let names: Vec<String> = (0..200_000).map(|i| format!("extra{i}")).collect();
    let header = format!("t,x,{}", names.join(","));
    let row = format!("0,1{}\n", ",".repeat(names.len()));
    let rows: String = (0..20).map(|_| row.as_str()).collect();
    std::fs::write(dir.join("wide.csv"), format!("{header}\n{rows}")).unwrap();
    let mut config = json(&workspace().join("experiments/learn.json"));
    config["padding"] = "x".repeat(50 << 20).into();
    std::fs::write(dir.join("big.json"), config.to_string()).unwrap();
    sine_csv(&dir);
    let learn = env!("CARGO_BIN_EXE_learn");
    let cases: [(&str, &[&str]); 3] = [
        ("columns in the header", &["data", "inspect", "wide.csv"]),
        (
            "character device",
            &[
                "mismatch",
                "--recording",
                "sine.csv",
                "--model",
                "/dev/zero",
                "--out",
                "m",
            ],
        ),
        ("MiB", &["meta-train", "--config", "big.json"]),
    ];
    for (needle, args) in cases {
        let start = Instant::now();
        // 1 GiB of address space: the 5 GB the wide header cost before is far out of reach.
        let output = Command::new("sh")
            .arg("-c")
            .arg("ulimit -v 1048576 && exec \"$@\"")
            .arg("sh")
            .arg(learn)
            .args(args)
            .current_dir(&dir)
            .env("RUST_BACKTRACE", "0")
            .output()
            .unwrap();
        let stderr = String::from_utf8_lossy(&output.stderr);
        assert_eq!(output.status.code(), Some(1), "{args:?}: {stderr}");
        assert_eq!(stderr.trim_end().lines().count(), 1, "{stderr}");
        assert!(stderr.contains(needle), "{needle}: {stderr}");
        assert!(
            start.elapsed() < Duration::from_secs(10),
            "{args:?} took too long"
        );
    }
}

/// Class 5: an output that cannot be written is refused before any work (no fit printed, no
/// checkpoint written, no training).
#[test]
fn unwritable_outputs_are_refused_before_any_work() {
    let dir = scratch("hostile-unwritable");
    sine_csv(&dir);
    let run = learn_in(
        &dir,
        &[
            "sindy",
            "--csv",
            "sine.csv",
            "--state",
            "x,y",
            "--out",
            "/proc/m.json",
        ],
    );
    run.one_line_error(&["/proc/m.json", "--out"]);
    assert!(
        run.stdout.is_empty(),
        "no work before the refusal: {}",
        run.stdout
    );
    let Some(data) = data::real_data_dir_for_tests(&workspace()) else {
        return;
    };
    let config = workspace().join("experiments/learn.json");
    let conditions = workspace().join("experiments/conditions.json");
    let start = Instant::now();
    let run = learn_in(
        &dir,
        &[
            "--data",
            data.to_str().unwrap(),
            "meta-train",
            "--conditions",
            conditions.to_str().unwrap(),
            "--config",
            config.to_str().unwrap(),
            "--checkpoints",
            "ck",
            "--out",
            "/proc/mt.json",
        ],
    );
    run.one_line_error(&["/proc/mt.json"]);
    assert!(!dir.join("ck").exists(), "no checkpoint, no folder");
    assert!(
        start.elapsed() < Duration::from_secs(10),
        "refused before training"
    );
}

/// A small nominal model file with `extra` spliced in after its opening brace.
fn model_with(dir: &Path, name: &str, prefix: &str, extra: &str) -> PathBuf {
    let text =
        std::fs::read_to_string(workspace().join("experiments/mismatch/neural-fly.json")).unwrap();
    let body = text.trim_start().strip_prefix('{').unwrap();
    let path = dir.join(name);
    std::fs::write(&path, format!("{prefix}{{{extra}{body}")).unwrap();
    path
}

/// Classes 6 and 7: one JSON policy (a key given twice refused by name, a BOM accepted), and
/// messages that name the field with short numbers.
#[test]
fn json_is_read_strictly_and_errors_are_plain() {
    let dir = scratch("hostile-json");
    model_with(&dir, "dup.json", "", "\"mass_kg\": 100.0, ");
    let run = learn_in(
        &dir,
        &[
            "mismatch",
            "--recording",
            "none.csv",
            "--model",
            "dup.json",
            "--out",
            "m",
        ],
    );
    run.one_line_error(&["dup.json", "mass_kg", "twice"]);
    // With a BOM the model is read; the run then stops at the missing recording.
    model_with(&dir, "bom.json", "\u{feff}", "");
    let run = learn_in(
        &dir,
        &[
            "mismatch",
            "--recording",
            "none.csv",
            "--model",
            "bom.json",
            "--out",
            "m",
        ],
    );
    run.one_line_error(&["none.csv"]);
    sine_csv(&dir);
    let run = learn_in(
        &dir,
        &[
            "sindy",
            "--csv",
            "sine.csv",
            "--state",
            "x",
            "--threshold",
            "-1e-300",
        ],
    );
    let message = run.one_line_error(&["-1e-300"]);
    assert!(message.len() < 200, "{message}");
    learn_in(&dir, &["meta-train", "--config", "sine.csv"])
        .one_line_error(&["sine.csv", "not JSON", "CSV"]);
    learn_in(&dir, &["meta-train", "--seed", "-1"]).one_line_usage_error(&["whole number"]);
    std::fs::write(dir.join("tex"), "").unwrap();
    let root = workspace();
    let root = root.to_str().unwrap();
    learn_in(
        &dir,
        &[
            "reproduce",
            "--root",
            root,
            "--config",
            &format!("{root}/experiments/reproduce.json"),
            "--out",
            "res",
            "--latex-dir",
            "tex",
        ],
    )
    .one_line_error(&["tex: is a file, not a directory (--latex-dir"]);
    let mut run_config = json(&workspace().join("experiments/reproduce.json"));
    run_config["conditions"] = "".into();
    std::fs::write(dir.join("r.json"), run_config.to_string()).unwrap();
    learn_in(&dir, &["reproduce", "--root", root, "--config", "r.json"]).one_line_error(&[
        "r.json",
        "conditions",
        "empty path",
    ]);
}

/// Class 8: a full standard error changes neither the exit code nor the file written.
#[test]
fn a_full_standard_error_changes_nothing() {
    let Ok(full) = std::fs::OpenOptions::new().write(true).open("/dev/full") else {
        return; // no /dev/full on this system
    };
    let dir = scratch("hostile-full-stderr");
    sine_csv(&dir);
    let status = Command::new(env!("CARGO_BIN_EXE_learn"))
        .args([
            "sindy", "--csv", "sine.csv", "--state", "x,y", "--out", "m.json",
        ])
        .current_dir(&dir)
        .stdout(Stdio::null())
        .stderr(full)
        .status()
        .unwrap();
    assert_eq!(status.code(), Some(0));
    assert!(sindy::SindyModel::load(&dir.join("m.json")).is_ok());
}
