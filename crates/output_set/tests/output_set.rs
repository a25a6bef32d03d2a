//! The output-set protocol on real folders: ownership, --force, stale files, locks, staging,
//! journals.

use std::path::Path;

use output_set::{Existing, OutputError, OutputSet};

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
) -> output_set::Result<()> {
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

/// Runs `producer` with the named file `path` (`--out`) holding `content`.
fn run_named(path: &Path, content: &str, existing: Existing) -> output_set::Result<()> {
    let mut set = OutputSet::new("sindy");
    let file = set.file(path, "--out", existing);
    let staged = set.prepare()?;
    std::fs::write(staged.path(file), content).unwrap();
    staged.commit().map(drop)
}

/// Makes a FIFO at `path`.
fn make_fifo(path: &Path) {
    let name = std::ffi::CString::new(path.as_os_str().as_encoded_bytes()).unwrap();
    // SAFETY: a valid NUL-terminated path inside the test's temporary folder.
    assert_eq!(unsafe { libc::mkfifo(name.as_ptr(), 0o644) }, 0);
}

/// Makes a character device node with /dev/null's numbers at `path` (inside the test's own
/// folder; nothing is ever written to it); `false` when not permitted (not root).
fn make_character_device(path: &Path) -> bool {
    let name = std::ffi::CString::new(path.as_os_str().as_encoded_bytes()).unwrap();
    // SAFETY: a valid NUL-terminated path inside the test's temporary folder.
    unsafe { libc::mknod(name.as_ptr(), libc::S_IFCHR | 0o666, libc::makedev(1, 3)) == 0 }
}

fn mode(path: &Path) -> u32 {
    use std::os::unix::fs::PermissionsExt;
    std::fs::metadata(path).unwrap().permissions().mode() & 0o7777
}

/// Issue 31, class 1: a named output is never a FIFO, device or socket (refused with or without
/// --force, left as it was), is written through a symbolic link into the file it leads to (the
/// link stays), and through the inode of a file with other hard links.
#[test]
fn named_outputs_never_replace_special_files_and_write_through_links() {
    use std::os::unix::fs::{FileTypeExt, MetadataExt};
    let tmp = scratch("special");
    let dir = tmp.path();
    let fifo = dir.join("model.fifo");
    make_fifo(&fifo);
    let socket = dir.join("model.sock");
    let _listener = std::os::unix::net::UnixListener::bind(&socket).unwrap();
    let device = dir.join("null");
    let mut special = vec![(fifo.clone(), "a FIFO"), (socket, "a socket")];
    if make_character_device(&device) {
        special.push((device.clone(), "a character device"));
    } else {
        eprintln!("not root: the character device case is skipped");
    }
    let link_to_fifo = dir.join("link-to-fifo.json");
    std::os::unix::fs::symlink(&fifo, &link_to_fifo).unwrap();
    special.push((link_to_fifo.clone(), "a FIFO"));
    for (path, kind) in &special {
        for existing in [Existing::Refuse, Existing::Replace] {
            let error = run_named(path, "{}", existing).unwrap_err();
            assert!(
                matches!(error, OutputError::NotRegularFile { .. }),
                "{existing:?}: {error}"
            );
            let message = error.to_string();
            assert!(message.contains(&path.display().to_string()), "{message}");
            assert!(message.contains(kind), "{message}");
        }
    }
    assert!(std::fs::metadata(&fifo).unwrap().file_type().is_fifo());
    assert!(
        std::fs::symlink_metadata(&link_to_fifo)
            .unwrap()
            .is_symlink()
    );
    if device.exists() {
        assert!(
            std::fs::metadata(&device)
                .unwrap()
                .file_type()
                .is_char_device()
        );
    }
    // A link to a README: the README is rewritten, the link stays a link.
    let readme = dir.join("README.md");
    std::fs::write(&readme, "old").unwrap();
    let link = dir.join("README-link.md");
    std::os::unix::fs::symlink("README.md", &link).unwrap();
    run_named(&link, "new", Existing::Replace).unwrap();
    assert!(std::fs::symlink_metadata(&link).unwrap().is_symlink());
    assert_eq!(std::fs::read_to_string(&readme).unwrap(), "new");
    let dangling = dir.join("dangling.json");
    std::os::unix::fs::symlink("missing/none.json", &dangling).unwrap();
    let error = run_named(&dangling, "x", Existing::Replace).unwrap_err();
    assert!(
        matches!(error, OutputError::LinkToNothing { .. }),
        "{error}"
    );
    // A file with a second hard link: written through its inode, both names see the new text.
    let linked = dir.join("linked.json");
    std::fs::write(&linked, "old").unwrap();
    std::fs::hard_link(&linked, dir.join("other-name.json")).unwrap();
    let inode = std::fs::metadata(&linked).unwrap().ino();
    run_named(&linked, "new text", Existing::Replace).unwrap();
    assert_eq!(std::fs::metadata(&linked).unwrap().ino(), inode);
    assert_eq!(
        std::fs::read_to_string(dir.join("other-name.json")).unwrap(),
        "new text"
    );
    assert!(
        !listing(dir)
            .iter()
            .any(|name| name.contains(".learn-staging-")),
        "{:?}",
        listing(dir)
    );
}

/// Issue 31, class 5: new files (named, in folders, the manifest) follow the umask; a replaced
/// file (named or in a folder) keeps its mode.
#[test]
fn modes_follow_the_umask_and_replaced_files_keep_theirs() {
    use std::os::unix::fs::PermissionsExt;
    // SAFETY: umask only changes this process's file creation mask (restored below).
    let previous = unsafe { libc::umask(0o002) };
    let tmp = scratch("modes");
    let dir = tmp.path();
    let named = dir.join("model.json");
    run_named(&named, "1", Existing::Refuse).unwrap();
    assert_eq!(mode(&named), 0o664, "a new named file");
    std::fs::set_permissions(&named, std::fs::Permissions::from_mode(0o640)).unwrap();
    run_named(&named, "2", Existing::Replace).unwrap();
    assert_eq!(mode(&named), 0o640, "a replaced named file");
    let out = dir.join("out");
    run(&out, "p", &[("t/a.json", "1")], Existing::Refuse).unwrap();
    assert_eq!(mode(&out.join("t/a.json")), 0o664, "a new file in a folder");
    assert_eq!(
        mode(&out.join(".learn-outputs.json")),
        0o664,
        "a new manifest"
    );
    assert_eq!(mode(&out.join("t")), 0o775, "a new subfolder");
    std::fs::set_permissions(out.join("t/a.json"), std::fs::Permissions::from_mode(0o600)).unwrap();
    run(&out, "p", &[("t/a.json", "2")], Existing::Replace).unwrap();
    assert_eq!(
        mode(&out.join("t/a.json")),
        0o600,
        "a replaced file in a folder"
    );
    // SAFETY: as above.
    unsafe { libc::umask(previous) };
}

/// Issue 31, class 2: a subfolder of an output folder that became a link to a foreign folder is
/// refused (before the work, and at the commit if it changed after), never written through; a
/// stale file is never removed through it.
#[test]
fn a_subfolder_that_became_a_link_is_refused_not_written_through() {
    let tmp = scratch("linked-subfolder");
    let out = tmp.path().join("out");
    let foreign = tmp.path().join("foreign");
    std::fs::create_dir(&foreign).unwrap();
    std::fs::write(foreign.join("a.svg"), "foreign a").unwrap();
    std::fs::write(foreign.join("old.svg"), "foreign old").unwrap();
    let files = [("figures/a.svg", "1"), ("figures/old.svg", "1")];
    run(&out, "p", &files, Existing::Refuse).unwrap();
    std::fs::remove_dir_all(out.join("figures")).unwrap();
    std::os::unix::fs::symlink(&foreign, out.join("figures")).unwrap();
    let before = listing(&foreign);
    // Through a planned file, and through a stale one (removed on commit).
    for files in [&[("figures/a.svg", "2")][..], &[("b.json", "2")][..]] {
        let error = run(&out, "p", files, Existing::Replace).unwrap_err();
        assert!(
            matches!(error, OutputError::NotMadeByLearn { .. }),
            "{error}"
        );
        assert!(
            error
                .to_string()
                .contains(&out.join("figures").display().to_string()),
            "{error}"
        );
    }
    // A link that appears after the checks is refused at the commit.
    std::fs::remove_file(out.join("figures")).unwrap();
    std::fs::create_dir(out.join("figures")).unwrap();
    let mut set = OutputSet::new("p");
    let folder = set.folder(&out, "--out", Existing::Replace);
    set.subfolder_in(folder, "figures");
    let staged = set.prepare().unwrap();
    std::fs::write(staged.dir(folder).join("figures/a.svg"), "2").unwrap();
    std::fs::remove_dir(out.join("figures")).unwrap();
    std::os::unix::fs::symlink(&foreign, out.join("figures")).unwrap();
    let error = staged.commit().unwrap_err();
    assert!(
        matches!(error, OutputError::NotMadeByLearn { .. }),
        "{error}"
    );
    assert_eq!(listing(&foreign), before);
    assert_eq!(
        std::fs::read_to_string(foreign.join("a.svg")).unwrap(),
        "foreign a"
    );
    assert_eq!(
        std::fs::read_to_string(foreign.join("old.svg")).unwrap(),
        "foreign old"
    );
    assert!(!out.join(".learn-commit.json").exists());
}

/// Issue 31, class 12: an error naming a staging path is put in final terms, also after its set
/// is gone (the error reaches the user once the set has been dropped).
#[test]
fn errors_name_final_paths_after_the_set_is_gone() {
    let tmp = scratch("final-terms");
    let out = tmp.path().join("out");
    let mut set = OutputSet::new("p");
    let folder = set.folder(&out, "--out", Existing::Refuse);
    set.subfolder_in(folder, "figures");
    let staged = set.prepare().unwrap();
    let message = format!(
        "{}: No space left on device",
        staged.dir(folder).join("figures/x.svg").display()
    );
    drop(staged);
    assert_eq!(
        output_set::in_final_terms(&message),
        format!(
            "{}: No space left on device",
            out.join("figures/x.svg").display()
        )
    );
}

/// A file to write that is also the folder of another output (however spelt, in a folder or
/// named) is refused before anything is made: it cannot be both.
#[test]
fn an_output_that_is_the_folder_of_another_is_refused() {
    let tmp = scratch("file-as-folder");
    let dir = tmp.path();
    let mut set = OutputSet::new("p");
    let out = set.folder(dir.join("out"), "--out", Existing::Refuse);
    set.file_in(out, "summary.json");
    set.file(
        dir.join("out/./sub/../summary.json/case/recording.csv"),
        "--work",
        Existing::Refuse,
    );
    let message = set.check().unwrap_err().to_string();
    assert!(
        message.contains("out/summary.json: is both a file to write (--out) and the folder of ")
            && message.contains("recording.csv (--work)"),
        "{message}"
    );
    assert!(matches!(
        set.prepare(),
        Err(OutputError::FileIsFolderOfAnother { .. })
    ));
    assert!(listing(dir).is_empty());
    // Side by side, they are fine.
    let mut set = OutputSet::new("p");
    let out = set.folder(dir.join("out"), "--out", Existing::Refuse);
    set.file_in(out, "summary.json");
    set.file(
        dir.join("out/case/recording.csv"),
        "--work",
        Existing::Refuse,
    );
    set.check().unwrap();
}
