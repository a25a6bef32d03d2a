//! The output-set protocol on real folders: ownership, --force, stale files, locks, staging,
//! journals.

use std::path::Path;

use outputs::{Existing, OutputError, OutputSet};

/// A fresh, empty temporary directory, removed with everything in it when dropped.
fn scratch(name: &str) -> tempfile::TempDir {
    tempfile::Builder::new()
        .prefix(&format!("outputs-{name}-"))
        .tempdir()
        .unwrap()
}

/// Runs `producer` into `dir`, writing `files` (relative name, content).
fn run(
    dir: &Path,
    producer: &str,
    files: &[(&str, &str)],
    existing: Existing,
) -> outputs::Result<()> {
    let mut set = OutputSet::new(producer);
    let folder = set.folder(dir, "--out", existing);
    for (name, _) in files {
        set.file_in(folder, name);
    }
    let staged = set.prepare()?;
    for (name, content) in files {
        let path = staged.dir(folder).join(name);
        std::fs::write(path, content).unwrap();
    }
    staged.commit().map(drop)
}

/// Every entry of `dir`, recursively, as sorted relative names.
fn listing(dir: &Path) -> Vec<String> {
    let mut names = Vec::new();
    let mut pending = vec![dir.to_path_buf()];
    while let Some(d) = pending.pop() {
        for entry in std::fs::read_dir(&d).unwrap().flatten() {
            let path = entry.path();
            names.push(path.strip_prefix(dir).unwrap().display().to_string());
            if path.is_dir() {
                pending.push(path);
            }
        }
    }
    names.sort();
    names
}

#[test]
fn own_files_are_replaced_only_with_force_and_foreign_ones_never() {
    let tmp = scratch("own");
    let dir = tmp.path().to_path_buf();
    run(
        &dir,
        "p",
        &[("a.json", "1"), ("t/b.md", "1")],
        Existing::Refuse,
    )
    .unwrap();
    assert_eq!(std::fs::read_to_string(dir.join("t/b.md")).unwrap(), "1");
    let again = run(&dir, "p", &[("a.json", "2")], Existing::Refuse).unwrap_err();
    assert!(matches!(again, OutputError::OwnExists { .. }), "{again}");
    std::fs::write(dir.join("t/notes.json"), "mine").unwrap();
    let foreign = run(&dir, "p", &[("t/notes.json", "x")], Existing::Replace).unwrap_err();
    assert!(matches!(foreign, OutputError::Foreign { .. }), "{foreign}");
    assert!(foreign.to_string().contains("t/notes.json"), "{foreign}");
    // With --force: a.json replaced, t/b.md (stale: not written again) removed, notes kept.
    run(&dir, "p", &[("a.json", "2")], Existing::Replace).unwrap();
    assert_eq!(std::fs::read_to_string(dir.join("a.json")).unwrap(), "2");
    assert!(!dir.join("t/b.md").exists());
    assert_eq!(
        std::fs::read_to_string(dir.join("t/notes.json")).unwrap(),
        "mine"
    );
    assert_eq!(
        listing(&dir),
        [".learn-outputs.json", "a.json", "t", "t/notes.json"]
    );
    let manifest = std::fs::read_to_string(dir.join(".learn-outputs.json")).unwrap();
    assert_eq!(
        manifest,
        "{\n  \"format\": \"learn-outputs/1\",\n  \"files\": {\n    \"a.json\": \"p\"\n  }\n}\n"
    );
    // Another producer's files in the same folder are left alone.
    run(&dir, "q", &[("q.json", "q")], Existing::Refuse).unwrap();
    run(&dir, "p", &[("a.json", "3")], Existing::Replace).unwrap();
    assert!(dir.join("q.json").exists());
}

#[test]
fn a_failed_or_dropped_run_leaves_the_old_set_and_no_staging() {
    let tmp = scratch("dropped");
    let dir = tmp.path().to_path_buf();
    run(
        &dir,
        "p",
        &[("a.json", "old"), ("b.json", "old")],
        Existing::Refuse,
    )
    .unwrap();
    let mut set = OutputSet::new("p");
    let folder = set.folder(&dir, "--out", Existing::Replace);
    set.file_in(folder, "a.json");
    let staged = set.prepare().unwrap();
    std::fs::write(staged.dir(folder).join("a.json"), "new").unwrap();
    drop(staged);
    assert_eq!(std::fs::read_to_string(dir.join("a.json")).unwrap(), "old");
    assert_eq!(listing(&dir), [".learn-outputs.json", "a.json", "b.json"]);
}

#[test]
fn a_second_run_into_a_locked_folder_is_refused() {
    let tmp = scratch("locked");
    let dir = tmp.path().to_path_buf();
    let mut first = OutputSet::new("p");
    let folder = first.folder(&dir, "--out", Existing::Refuse);
    first.file_in(folder, "a.json");
    let staged = first.prepare().unwrap();
    let mut second = OutputSet::new("p");
    let other = second.folder(dir.join("."), "--out", Existing::Refuse);
    second.file_in(other, "b.json");
    let error = second.prepare().unwrap_err();
    assert!(matches!(error, OutputError::Locked { .. }), "{error}");
    assert!(error.to_string().contains("another learn run"), "{error}");
    drop(staged);
}

#[test]
fn named_files_need_force_and_outputs_are_never_inputs() {
    let tmp = scratch("named");
    let dir = tmp.path().to_path_buf();
    let target = dir.join("m.json");
    std::fs::write(&target, "old").unwrap();
    let mut set = OutputSet::new("sindy");
    set.file(&target, "--out", Existing::Refuse);
    assert!(matches!(
        set.check().unwrap_err(),
        OutputError::Exists { .. }
    ));
    let mut set = OutputSet::new("sindy");
    set.input("the --csv input", dir.join("./m.json"));
    set.file(&target, "--out", Existing::Replace);
    assert!(matches!(
        set.check().unwrap_err(),
        OutputError::OutputIsInput { .. }
    ));
    let mut set = OutputSet::new("sindy");
    let file = set.file(&target, "--out", Existing::Replace);
    let staged = set.prepare().unwrap();
    std::fs::write(staged.path(file), "new").unwrap();
    assert_eq!(std::fs::read_to_string(&target).unwrap(), "old");
    staged.commit().unwrap();
    assert_eq!(std::fs::read_to_string(&target).unwrap(), "new");
    assert_eq!(listing(&dir), ["m.json"]);
    let mut set = OutputSet::new("x");
    set.folder(&target, "--latex-dir", Existing::Refuse);
    let error = set.check().unwrap_err().to_string();
    assert!(
        error.contains("is a file, not a directory (--latex-dir"),
        "{error}"
    );
}

#[test]
fn a_killed_commit_is_finished_and_dead_staging_removed_by_the_next_run() {
    let tmp = scratch("journal");
    let dir = tmp.path().to_path_buf();
    run(&dir, "p", &[("a.json", "old")], Existing::Refuse).unwrap();
    // What a commit killed after its journal and before its renames leaves behind (pid 0 is never
    // a user process's staging: take an unused high pid for the dead one).
    let dead = dir.join(".learn-staging-999999999-abc");
    std::fs::create_dir_all(&dead).unwrap();
    std::fs::write(dead.join("a.json"), "new").unwrap();
    std::fs::write(
        dir.join(".learn-commit.json"),
        r#"{"staging": ".learn-staging-999999999-abc", "moves": ["a.json"], "removals": [],
            "manifest": {"format": "learn-outputs/1", "files": {"a.json": "p"}}}"#,
    )
    .unwrap();
    run(&dir, "q", &[("q.json", "q")], Existing::Refuse).unwrap();
    assert_eq!(std::fs::read_to_string(dir.join("a.json")).unwrap(), "new");
    assert_eq!(listing(&dir), [".learn-outputs.json", "a.json", "q.json"]);
}

/// A run killed (SIGKILL) while it probed a subfolder leaves its probe file there; the next run
/// into the folder removes it (it removed dead staging only in the folder itself).
#[test]
fn a_dead_probe_in_a_subfolder_is_removed_by_the_next_run() {
    let tmp = scratch("dead-probe");
    let dir = tmp.path().to_path_buf();
    run(&dir, "p", &[("figures/a.svg", "1")], Existing::Refuse).unwrap();
    let probe = dir.join("figures/.learn-staging-999999999-probe");
    std::fs::write(&probe, "").unwrap();
    run(&dir, "p", &[("figures/a.svg", "2")], Existing::Replace).unwrap();
    assert!(!probe.exists(), "{:?}", listing(&dir));
    assert_eq!(
        listing(&dir),
        [".learn-outputs.json", "figures", "figures/a.svg"]
    );
}

#[test]
fn a_manifest_cannot_reach_outside_its_folder() {
    let tmp = scratch("reach");
    let dir = tmp.path().to_path_buf();
    std::fs::write(
        dir.join(".learn-outputs.json"),
        r#"{"format": "learn-outputs/1", "files": {"../x": "p"}}"#,
    )
    .unwrap();
    let error = run(&dir, "p", &[("a.json", "1")], Existing::Replace).unwrap_err();
    assert!(
        error.to_string().contains("not a plain relative path"),
        "{error}"
    );
}

/// A set of two folders whose second cannot take its commit journal: the first folder keeps its
/// old files (no folder of the set is committed alone) and no journal is left to finish later.
#[test]
fn a_commit_that_fails_in_one_folder_changes_none() {
    let tmp = scratch("two-folders");
    let dir = tmp.path().to_path_buf();
    let (first, second) = (dir.join("a"), dir.join("b"));
    for (folder, content) in [(&first, "old a"), (&second, "old b")] {
        run(folder, "p", &[("x.json", content)], Existing::Refuse).unwrap();
    }
    let mut set = OutputSet::new("p");
    let folder_a = set.folder(&first, "--out", Existing::Replace);
    let folder_b = set.folder(&second, "--latex-dir", Existing::Replace);
    set.file_in(folder_a, "x.json");
    set.file_in(folder_b, "x.json");
    let staged = set.prepare().unwrap();
    std::fs::write(staged.dir(folder_a).join("x.json"), "new a").unwrap();
    std::fs::write(staged.dir(folder_b).join("x.json"), "new b").unwrap();
    // A directory where the second folder's journal goes: its atomic write cannot rename onto it.
    std::fs::create_dir_all(second.join(".learn-commit.json/blocked")).unwrap();
    assert!(staged.commit().is_err());
    assert_eq!(
        std::fs::read_to_string(first.join("x.json")).unwrap(),
        "old a"
    );
    assert_eq!(
        std::fs::read_to_string(second.join("x.json")).unwrap(),
        "old b"
    );
    assert!(!first.join(".learn-commit.json").exists());
}
