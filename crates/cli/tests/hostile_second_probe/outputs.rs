//! Outputs (issue 31, classes 1, 2, 4, 5 and the first half of 12): named outputs never replace
//! special files and write through links, keeping the file's mode; new files follow the umask;
//! a subfolder that became a link is refused; the two-folder commit of `reproduce`/`merge`
//! survives SIGKILL at every point of the commit and SIGINT while writing; a full disk names the
//! final path. The merges run on a small generated experiment (`common::sweep`): one shard run per
//! configuration, then merges of a fraction of a second each.

use std::collections::BTreeMap;
use std::os::unix::fs::{FileTypeExt, PermissionsExt};
use std::os::unix::process::ExitStatusExt;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use serde_json::json;

use super::common::sweep::{SmallExperiment, files_under, small_experiment};
use super::common::{Run, scratch};

/// The test hook `learn` honours in test builds: stop with a signal at a named point.
const SIGNAL_AT: &str = "LEARN_TEST_SIGNAL_AT";
/// Files that differ between two runs of the same merge (wall times).
const PROVENANCE_ONLY: [&str; 1] = ["timings.json"];
/// The README every merge updates, with its generated block.
const README: &str = "# Results\n\n<!-- tables:begin -->\n<!-- tables:end -->\n";

/// Runs `learn args` in `dir` under `umask` with `environment`; the raw output.
fn learn_with(dir: &Path, umask: &str, environment: &[(&str, &str)], args: &[&str]) -> Output {
    let mut command = Command::new("sh");
    command
        .arg("-c")
        .arg(format!("umask {umask}; exec \"$0\" \"$@\""))
        .arg(env!("CARGO_BIN_EXE_learn"))
        .args(args)
        .current_dir(dir)
        .env_remove("NEURAL_FLY_DIR")
        .env_remove(SIGNAL_AT)
        .env("RUST_BACKTRACE", "0");
    for (name, value) in environment {
        command.env(name, value);
    }
    command.output().expect("the learn binary runs")
}

/// As [`learn_with`], umask 022 and no hook, as a [`Run`].
fn learn(dir: &Path, args: &[&str]) -> Run {
    let output = learn_with(dir, "022", &[], args);
    Run {
        code: output.status.code(),
        stdout: String::from_utf8_lossy(&output.stdout).into_owned(),
        stderr: String::from_utf8_lossy(&output.stderr).into_owned(),
    }
}

fn mode(path: &Path) -> u32 {
    std::fs::metadata(path).unwrap().permissions().mode() & 0o7777
}

fn path_text(path: &Path) -> &str {
    path.to_str().expect("UTF-8 path")
}

/// A CSV `t,x,y` of a sine and a cosine, 200 rows.
fn sine_csv(dir: &Path) {
    let rows: String = (0..200)
        .map(|i| {
            let t = f64::from(i) * 0.01;
            format!("{t},{},{}\n", t.sin(), t.cos())
        })
        .collect();
    std::fs::write(dir.join("sine.csv"), format!("t,x,y\n{rows}")).unwrap();
}

fn sindy_into(dir: &Path, umask: &str, out: &str, force: bool) -> Output {
    let mut args = vec!["sindy", "--csv", "sine.csv", "--state", "x,y", "--out", out];
    if force {
        args.push("--force");
    }
    learn_with(dir, umask, &[], &args)
}

fn make_fifo(path: &Path) {
    let name = std::ffi::CString::new(path.as_os_str().as_encoded_bytes()).unwrap();
    // SAFETY: a valid NUL-terminated path inside the test's own temporary folder.
    assert_eq!(unsafe { libc::mkfifo(name.as_ptr(), 0o644) }, 0);
}

/// A character device node with /dev/null's numbers, made inside the test's own folder (nothing
/// is ever written to the machine's /dev); `false` when not permitted (not root).
fn make_character_device(path: &Path) -> bool {
    let name = std::ffi::CString::new(path.as_os_str().as_encoded_bytes()).unwrap();
    // SAFETY: a valid NUL-terminated path inside the test's own temporary folder.
    unsafe { libc::mknod(name.as_ptr(), libc::S_IFCHR | 0o666, libc::makedev(1, 3)) == 0 }
}

/// Asserts `output` is the one-line error of exit code 1 naming every needle.
fn assert_one_line_error(output: &Output, needles: &[&str]) {
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert_eq!(output.status.code(), Some(1), "{stderr}");
    let message = stderr.trim_end();
    assert_eq!(message.lines().count(), 1, "{message}");
    assert!(message.starts_with("error: "), "{message}");
    for needle in needles {
        assert!(message.contains(needle), "{needle:?} missing: {message}");
    }
}

/// Class 1 and 5 with `sindy --out`: a FIFO and a character device are refused with or without
/// --force and stay what they are; a link is written through (the link stays, the file it leads
/// to gets the model and keeps its mode 0664 under umask 022); a new file follows the umask.
#[test]
fn named_outputs_are_written_through_links_and_never_replace_special_files() {
    let dir = scratch("second-probe-named");
    sine_csv(&dir);
    make_fifo(&dir.join("model.fifo"));
    let mut special = vec![("model.fifo", "a FIFO")];
    if make_character_device(&dir.join("null")) {
        special.push(("null", "a character device"));
    } else {
        eprintln!("not root: the character device case is skipped");
    }
    for (name, kind) in &special {
        for force in [false, true] {
            let output = sindy_into(&dir, "022", name, force);
            assert_one_line_error(&output, &[name, kind, "not a regular file"]);
        }
    }
    assert!(
        std::fs::metadata(dir.join("model.fifo"))
            .unwrap()
            .file_type()
            .is_fifo()
    );
    if special.len() == 2 {
        let device = std::fs::metadata(dir.join("null")).unwrap();
        assert!(device.file_type().is_char_device());
    }
    std::fs::write(dir.join("model.json"), "old").unwrap();
    std::fs::set_permissions(dir.join("model.json"), PermissionsExt::from_mode(0o664)).unwrap();
    std::os::unix::fs::symlink("model.json", dir.join("link.json")).unwrap();
    let output = sindy_into(&dir, "022", "link.json", true);
    assert!(output.status.success(), "{output:?}");
    assert!(
        std::fs::symlink_metadata(dir.join("link.json"))
            .unwrap()
            .is_symlink()
    );
    let model = std::fs::read_to_string(dir.join("model.json")).unwrap();
    assert!(model.contains("\"sindy-model/1\""), "{model}");
    assert_eq!(
        mode(&dir.join("model.json")),
        0o664,
        "the file's mode is kept"
    );
    let output = sindy_into(&dir, "027", "new.json", false);
    assert!(output.status.success(), "{output:?}");
    assert_eq!(mode(&dir.join("new.json")), 0o640, "umask 027");
    let hidden = hidden_entries(&dir, ".learn-staging-");
    assert!(hidden.is_empty(), "{hidden:?}");
}

/// A small experiment with two reproduce shards of different results (seeds 1, 2 and seed 3):
/// merging the first, then the second, replaces every file's content.
struct TwoShards {
    _scratch: super::common::Scratch,
    dir: PathBuf,
    old: PathBuf,
    new: PathBuf,
    /// `learn … reproduce --shard 0/1` of the first configuration, without `--out`.
    shard_run: Vec<String>,
}

fn two_shards(name: &str) -> TwoShards {
    let scratch = scratch(name);
    let dir = scratch.to_path_buf();
    let experiment = small_experiment(&dir);
    let mut config: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&experiment.run).unwrap()).unwrap();
    config["learn"]["seeds"] = json!([3]);
    let other_run = dir.join("run-seed-3.json");
    std::fs::write(&other_run, config.to_string()).unwrap();
    let data = SmallExperiment::arg(&experiment.data);
    let shard_run = |config: &Path| -> Vec<String> {
        let root = path_text(&dir);
        let args = [
            "--quiet",
            "--data",
            data,
            "reproduce",
            "--root",
            root,
            "--config",
        ];
        let mut args: Vec<String> = args.iter().map(|a| a.to_string()).collect();
        args.extend([path_text(config), "--shard", "0/1"].map(String::from));
        args
    };
    for (config, shard) in [(&experiment.run, "old"), (&other_run, "new")] {
        let mut args = shard_run(config);
        args.extend(["--out".to_string(), shard.to_string()]);
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        learn(&dir, &args).success();
    }
    TwoShards {
        old: dir.join("old"),
        new: dir.join("new"),
        shard_run: shard_run(&experiment.run),
        dir,
        _scratch: scratch,
    }
}

/// The arguments of `learn merge SHARD --out OUT --latex-dir LATEX [--readme R] --force`.
fn merge_args<'a>(
    shard: &'a Path,
    out: &'a str,
    latex: &'a str,
    readme: Option<&'a str>,
) -> Vec<&'a str> {
    let mut args = vec![
        "merge",
        path_text(shard),
        "--out",
        out,
        "--latex-dir",
        latex,
    ];
    if let Some(readme) = readme {
        args.extend(["--readme", readme]);
    }
    args.push("--force");
    args
}

/// Class 2: `U/figures` replaced by a link to a foreign folder holding a file of the same name
/// as a figure: the next merge with --force is refused naming it, and writes nothing there.
#[test]
fn a_subfolder_that_became_a_link_is_refused_not_written_through() {
    let shards = two_shards("second-probe-linked-subfolder");
    let dir = &shards.dir;
    learn(dir, &merge_args(&shards.old, "U", "L", None)).success();
    let figures = files_under(&dir.join("U/figures"), &[]);
    let (figure, _) = figures.first_key_value().expect("the merge drew figures");
    let foreign = dir.join("foreign");
    std::fs::create_dir(&foreign).unwrap();
    std::fs::write(foreign.join(figure), "not learn's").unwrap();
    std::fs::remove_dir_all(dir.join("U/figures")).unwrap();
    std::os::unix::fs::symlink(&foreign, dir.join("U/figures")).unwrap();
    let run = learn(dir, &merge_args(&shards.new, "U", "L", None));
    run.one_line_error(&["U/figures", "a symbolic link", "not the folder learn made"]);
    let left = files_under(&foreign, &[]);
    assert_eq!(left.len(), 1, "{:?}", left.keys());
    assert_eq!(left[figure.as_path()], b"not learn's");
}

/// Every file of `dir` but the provenance, and but the staging and journal of a commit that did
/// not happen (hidden, removed by the next run into the folder).
fn set_of(dir: &Path) -> BTreeMap<PathBuf, Vec<u8>> {
    let mut files = files_under(dir, &PROVENANCE_ONLY);
    files.retain(|path, _| {
        let first = path
            .components()
            .next()
            .unwrap()
            .as_os_str()
            .to_string_lossy();
        !first.starts_with(".learn-staging-") && first != ".learn-commit.json"
    });
    files
}

/// What a merge of `shard` writes into fresh folders: (results, LaTeX, README).
fn reference_set(shards: &TwoShards, shard: &Path, name: &str) -> [BTreeMap<PathBuf, Vec<u8>>; 3] {
    let base = shards.dir.join(name);
    std::fs::create_dir(&base).unwrap();
    std::fs::write(base.join("README.md"), README).unwrap();
    let args = merge_args(shard, "U", "L", Some("README.md"));
    learn(&base, &args).success();
    let readme = std::fs::read(base.join("README.md")).unwrap();
    [
        set_of(&base.join("U")),
        set_of(&base.join("L")),
        BTreeMap::from([(PathBuf::from("README.md"), readme)]),
    ]
}

/// The signal points a merge into two folders and a README passes (the hook's `list`).
fn signal_points(shards: &TwoShards) -> Vec<String> {
    let base = shards.dir.join("points");
    std::fs::create_dir(&base).unwrap();
    std::fs::write(base.join("README.md"), README).unwrap();
    let args = merge_args(&shards.new, "U", "L", Some("README.md"));
    let output = learn_with(&base, "022", &[(SIGNAL_AT, "list")], &args);
    assert!(output.status.success(), "{output:?}");
    String::from_utf8_lossy(&output.stderr)
        .lines()
        .filter_map(|line| line.strip_prefix("signal point: "))
        .map(str::to_string)
        .collect()
}

/// Class 4: a merge into `--out U --latex-dir L --readme README.md` (the old set there) killed
/// with SIGKILL at every point of its commit; the next run into ONE of the two folders (a shard
/// run, which adds its `shard.json` and leaves the merged files alone) finishes or undoes the
/// commit everywhere: both folders and the README hold the old set whole (killed before the
/// commit point) or the new set whole (after it); never a mix.
#[test]
fn the_two_folder_commit_survives_sigkill_at_every_point() {
    let shards = two_shards("second-probe-sigkill");
    let old = reference_set(&shards, &shards.old, "reference-old");
    let new = reference_set(&shards, &shards.new, "reference-new");
    assert!(old[0] != new[0] && old[1] != new[1] && old[2] != new[2]);
    let points = signal_points(&shards);
    let armed = points
        .iter()
        .position(|p| p == "armed")
        .expect("an arming point");
    assert!(points.len() >= 12, "{points:?}");
    for (index, point) in points.iter().enumerate() {
        let base = shards.dir.join(format!("kill-{index}"));
        std::fs::create_dir(&base).unwrap();
        std::fs::write(base.join("README.md"), README).unwrap();
        let into_both = merge_args(&shards.old, "U", "L", Some("README.md"));
        learn(&base, &into_both).success();
        let args = merge_args(&shards.new, "U", "L", Some("README.md"));
        let kill = format!("KILL@{point}");
        let output = learn_with(&base, "022", &[(SIGNAL_AT, &kill)], &args);
        assert_eq!(
            output.status.signal(),
            Some(libc::SIGKILL),
            "{point}: {output:?}"
        );
        let mut next = shards.shard_run.clone();
        next.extend(["--out".to_string(), ["U", "L"][index % 2].to_string()]);
        let next: Vec<&str> = next.iter().map(String::as_str).collect();
        learn(&base, &next).success();
        let expected = if index < armed { &old } else { &new };
        for (folder, expected) in ["U", "L"].iter().zip(expected) {
            let mut found = set_of(&base.join(folder));
            found.retain(|path, _| {
                !path.ends_with("shard.json") && !path.ends_with(".learn-outputs.json")
            });
            let mut expected = expected.clone();
            expected.remove(Path::new(".learn-outputs.json"));
            assert!(
                found == expected,
                "{point}: {folder} is not the {} set: {:?}",
                if index < armed { "old" } else { "new" },
                found.keys()
            );
        }
        let readme = std::fs::read(base.join("README.md")).unwrap();
        assert!(
            readme == expected[2][Path::new("README.md")],
            "{point}: README"
        );
        // A journal left in a folder the next run did not write is of a commit that moved
        // nothing (unarmed: undone by the next run into its folder) or that moved everything
        // (the lead's, removed last: nothing is left in its staging).
        for path in hidden_entries(&base, ".learn-commit") {
            let text = std::fs::read_to_string(&path).unwrap();
            let journal: serde_json::Value = serde_json::from_str(&text).unwrap();
            let staging = path.with_file_name(journal["staging"].as_str().unwrap());
            let pending = staging.exists() && !files_under(&staging, &[]).is_empty();
            assert!(journal["armed"] == false || !pending, "{point}: {text}");
        }
        // Staging of a run killed before its commit is removed by the next run into its folder.
        learn(&base, &args).success();
        let hidden = hidden_entries(&base, ".learn-");
        assert!(
            hidden.iter().all(|p| p.ends_with(".learn-outputs.json")),
            "{point}: left {hidden:?}"
        );
    }
}

/// Every file or folder under `dir` whose name starts with `prefix`.
fn hidden_entries(dir: &Path, prefix: &str) -> Vec<PathBuf> {
    let mut found = Vec::new();
    let mut pending = vec![dir.to_path_buf()];
    while let Some(next) = pending.pop() {
        for entry in std::fs::read_dir(&next).unwrap() {
            let path = entry.unwrap().path();
            let name = path.file_name().unwrap().to_string_lossy().into_owned();
            if name.starts_with(prefix) {
                found.push(path.clone());
            }
            if std::fs::symlink_metadata(&path).unwrap().is_dir() {
                pending.push(path);
            }
        }
    }
    found
}

/// Class 4: when the lead folder's journal of a killed two-folder commit is gone, the next run
/// into the other folder cannot tell finish from undo: it refuses, naming both, and changes
/// nothing.
#[test]
fn a_killed_commit_whose_lead_journal_is_gone_is_refused() {
    let shards = two_shards("second-probe-lost-journal");
    let base = &shards.dir;
    learn(base, &merge_args(&shards.old, "U", "L", None)).success();
    let args = merge_args(&shards.new, "U", "L", None);
    let output = learn_with(base, "022", &[(SIGNAL_AT, "KILL@journal 1 written")], &args);
    assert_eq!(output.status.signal(), Some(libc::SIGKILL), "{output:?}");
    std::fs::remove_file(base.join("U/.learn-commit.json")).unwrap();
    let before = set_of(&base.join("L"));
    let run = learn(base, &merge_args(&shards.new, "U2", "L", None));
    run.one_line_error(&[
        "L/.learn-commit.json",
        "cannot tell whether to finish or undo",
    ]);
    assert!(set_of(&base.join("L")) == before);
}

/// Class 4: SIGINT while the merge makes its staging subfolders (the signal thread removes the
/// staging under it, so making them fails): exit 130 without an error of its own (it was exit 1,
/// naming a staging path), the old set whole, no staging left.
#[test]
fn an_interrupt_while_writing_exits_130_and_leaves_the_old_set() {
    let shards = two_shards("second-probe-sigint");
    let base = &shards.dir;
    std::fs::write(base.join("README.md"), README).unwrap();
    learn(base, &merge_args(&shards.old, "U", "L", Some("README.md"))).success();
    let before = [set_of(&base.join("U")), set_of(&base.join("L"))];
    let readme = std::fs::read(base.join("README.md")).unwrap();
    for point in ["--out: staged", "--latex-dir: staged", "prepared"] {
        let args = merge_args(&shards.new, "U", "L", Some("README.md"));
        let interrupt = format!("INT@{point}");
        let output = learn_with(base, "022", &[(SIGNAL_AT, &interrupt)], &args);
        let stderr = String::from_utf8_lossy(&output.stderr);
        assert_eq!(output.status.code(), Some(130), "{point}: {stderr}");
        assert!(!stderr.contains("error"), "{point}: {stderr}");
        assert!([set_of(&base.join("U")), set_of(&base.join("L"))] == before);
        assert!(std::fs::read(base.join("README.md")).unwrap() == readme);
        let hidden = hidden_entries(base, ".learn-staging-");
        assert!(hidden.is_empty(), "left {hidden:?}");
    }
}

/// A tmpfs of `size` mounted on a fresh folder, unmounted when dropped.
struct SmallDisk(PathBuf);

impl SmallDisk {
    /// `None` when mounting is not permitted (not root, or no tmpfs).
    fn mount(at: &Path, size: &str) -> Option<Self> {
        std::fs::create_dir(at).unwrap();
        let status = Command::new("mount")
            .args(["-t", "tmpfs", "-o", &format!("size={size}"), "tmpfs"])
            .arg(at)
            .stderr(std::process::Stdio::null())
            .status()
            .ok()?;
        status.success().then(|| Self(at.to_path_buf()))
    }
}

impl Drop for SmallDisk {
    fn drop(&mut self) {
        let _ = Command::new("umount").arg(&self.0).status();
    }
}

/// Class 12: a full disk while the merge writes its figures: the error names the final path
/// (`U/…`), never the staging folder, and nothing is left on the disk.
#[test]
fn a_full_disk_names_the_final_path() {
    let shards = two_shards("second-probe-full-disk");
    let disk_path = shards.dir.join("disk");
    let Some(disk) = SmallDisk::mount(&disk_path, "64k") else {
        eprintln!("mounting a tmpfs is not permitted here: the full-disk case is skipped");
        return;
    };
    let out = disk.0.join("U");
    let run = learn(
        &shards.dir,
        &merge_args(&shards.old, path_text(&out), "L", None),
    );
    let message = run.one_line_error(&["No space left on device"]);
    assert!(!message.contains(".learn-staging-"), "{message}");
    assert!(
        message.contains(&format!("{}/", out.display())),
        "{message}"
    );
    let left = hidden_entries(&disk.0, "");
    assert!(left.is_empty(), "{left:?}");
}
