//! Preparing a checked [`OutputSet`] (lock, recover, probe, stage) and committing it (journals,
//! renames, manifests; see [`crate::journal`]).

use std::fs::File;
use std::path::{Path, PathBuf};
use std::sync::Mutex;

use fs4::FileExt;
use tempfile::{TempDir, TempPath};

use crate::error::{OutputError, Result, io};
use crate::journal::{self, Journal, NamedMove};
use crate::manifest::{self, Manifest};
use crate::paths::{self, Leaf};
use crate::{Existing, FileId, FilePlan, FolderId, FolderPlan, OutputSet, signals, test_hooks};

/// Every staging name starts so (hidden; ignored by git; removed by the next run).
const STAGING: &str = ".learn-staging-";

/// The prefix of this process's staging names: `.learn-staging-<pid>-`.
pub(crate) fn staging_prefix() -> String {
    format!("{STAGING}{}-", std::process::id())
}

/// Every staging path this process made, with the final path it stands for; kept for the
/// process's life, so an error reported after its set is gone is still put in final terms.
static FINAL_NAMES: Mutex<Vec<(String, String)>> = Mutex::new(Vec::new());

fn record_final_name(staging: &Path, final_path: &Path) {
    let mut names = FINAL_NAMES
        .lock()
        .unwrap_or_else(|poisoned| poisoned.into_inner());
    names.push((
        staging.display().to_string(),
        final_path.display().to_string(),
    ));
}

/// `message` (an error of a writer given staging paths) in terms of the final paths: every
/// staging path this process made replaced by what it stands for (a named file's staging by the
/// name given, a folder's staging by the folder).
pub fn in_final_terms(message: &str) -> String {
    let names = FINAL_NAMES
        .lock()
        .unwrap_or_else(|poisoned| poisoned.into_inner());
    // Longer first: no staging path is then replaced inside a longer one.
    let mut sorted: Vec<&(String, String)> = names.iter().collect();
    sorted.sort_by_key(|(staging, _)| std::cmp::Reverse(staging.len()));
    sorted
        .into_iter()
        .fold(message.to_string(), |text, (staging, final_path)| {
            text.replace(staging.as_str(), final_path)
        })
}

/// A prepared output set: folders locked, staging made. Dropping it without
/// [`Staged::commit`] removes the staging and leaves every output as it was.
#[derive(Debug)]
pub struct Staged {
    producer: String,
    remove_stale: bool,
    /// Folders that `prepare` created, outermost first: removed again (when empty) if the set
    /// is dropped without a commit.
    created: Vec<PathBuf>,
    committed: bool,
    folders: Vec<StagedFolder>,
    files: Vec<StagedFile>,
}

#[derive(Debug)]
struct StagedFolder {
    plan: FolderPlan,
    /// The folder, absolute and resolved (as the journals name it).
    resolved: PathBuf,
    /// The open folder, locked while the set lives.
    _lock: File,
    staging: TempDir,
}

#[derive(Debug)]
struct StagedFile {
    plan: FilePlan,
    /// The file written: the path named, or the file a symbolic link there leads to.
    target: PathBuf,
    staging: TempPath,
}

pub(crate) fn prepare(set: OutputSet) -> Result<Staged> {
    let mut staged = Staged {
        producer: set.producer.clone(),
        remove_stale: set.remove_stale,
        created: Vec::new(),
        committed: false,
        folders: Vec::new(),
        files: Vec::new(),
    };
    // On an error below, dropping `staged` removes what was made so far.
    let mut locked = Vec::new();
    for plan in &set.folders {
        locked.push(lock_folder(plan, &mut staged.created)?);
    }
    {
        // Every folder is locked before a killed commit is finished or undone: it may span
        // several of them. An interrupt waits for it, as for any commit.
        let _registry = signals::hold_installed();
        let held: Vec<PathBuf> = locked.iter().map(|(dir, _)| dir.clone()).collect();
        for plan in &set.folders {
            journal::recover(&plan.dir, &held)?;
        }
    }
    for (plan, (resolved, lock)) in set.folders.iter().zip(locked) {
        let folder = stage_folder(plan, resolved, lock, &mut staged.created)?;
        staged.folders.push(folder);
    }
    // Under the locks: what another run may have committed meanwhile is checked again.
    set.check()?;
    for plan in &set.files {
        let file = prepare_file(plan, &mut staged.created)?;
        staged.files.push(file);
    }
    let staging: Vec<&Path> = staged.staging_paths().collect();
    test_hooks::point(format_args!("prepared"), &staging);
    Ok(staged)
}

/// Creates `dir` and its missing parents, recording those it created in `created`.
fn create_dir(dir: &Path, option: &str, created: &mut Vec<PathBuf>) -> Result<()> {
    let missing: Vec<PathBuf> = dir
        .ancestors()
        .filter(|a| !a.as_os_str().is_empty() && !a.exists())
        .map(Path::to_path_buf)
        .collect();
    std::fs::create_dir_all(dir).map_err(not_writable(dir, option))?;
    created.extend(missing.into_iter().rev());
    Ok(())
}

fn not_writable(path: &Path, option: &str) -> impl FnOnce(std::io::Error) -> OutputError {
    let path = path.to_path_buf();
    let option = option.to_string();
    move |source| OutputError::NotWritable {
        path,
        option,
        source,
    }
}

/// Creates and locks the folder; returns it resolved (absolute) with its lock.
fn lock_folder(plan: &FolderPlan, created: &mut Vec<PathBuf>) -> Result<(PathBuf, File)> {
    let dir = &plan.dir;
    create_dir(dir, &plan.option, created)?;
    let lock = File::open(dir).map_err(not_writable(dir, &plan.option))?;
    if FileExt::try_lock(&lock).is_err() {
        return Err(OutputError::Locked {
            dir: dir.clone(),
            option: plan.option.clone(),
        });
    }
    let resolved = dir
        .canonicalize()
        .map_err(not_writable(dir, &plan.option))?;
    Ok((resolved, lock))
}

/// Removes dead staging from the locked folder, stages it, and probes every subfolder of a
/// planned file (each checked to be a folder `learn` made, not a link to another).
fn stage_folder(
    plan: &FolderPlan,
    resolved: PathBuf,
    lock: File,
    created: &mut Vec<PathBuf>,
) -> Result<StagedFolder> {
    let dir = &plan.dir;
    remove_dead_staging(dir);
    let staging = signals::create_registered(
        || {
            tempfile::Builder::new()
                .prefix(&staging_prefix())
                .tempdir_in(dir)
                .map_err(not_writable(dir, &plan.option))
        },
        |staging| staging.path().to_path_buf(),
    )?;
    record_final_name(staging.path(), dir);
    test_hooks::point(format_args!("{}: staged", plan.option), &[staging.path()]);
    let parents = plan.files.iter().filter_map(|r| r.parent());
    for parent in parents.chain(plan.subfolders.iter().map(PathBuf::as_path)) {
        if parent.as_os_str().is_empty() {
            continue;
        }
        refuse_foreign_folder(dir, parent, &plan.option)?;
        let target = dir.join(parent);
        create_dir(&target, &plan.option, created)?;
        // A run killed while it probed this subfolder left its probe here.
        remove_dead_staging(&target);
        probe(&target, &plan.option)?;
        create_inside(staging.path(), parent)?;
    }
    Ok(StagedFolder {
        plan: plan.clone(),
        resolved,
        _lock: lock,
        staging,
    })
}

/// An error when a component of the subfolder `relative` of `dir` is not a folder `learn` made.
pub(crate) fn refuse_foreign_folder(dir: &Path, relative: &Path, option: &str) -> Result<()> {
    match paths::first_foreign_component(dir, relative, Leaf::Folder) {
        Some((path, kind)) => Err(OutputError::NotMadeByLearn {
            path,
            kind,
            expected: Leaf::Folder,
            option: option.to_string(),
        }),
        None => Ok(()),
    }
}

/// Creates the missing folders above `path`, as `create_dir_all` would, except a staging folder
/// (`.learn-staging-*`, made by this crate only): one that an interrupt removed stays removed
/// (made again by a writer still at work, it would outlive the process) and the write fails
/// instead, which the caller reports only after [`crate::wait_if_interrupted`].
pub fn create_parent_folders(path: &Path) -> std::io::Result<()> {
    let Some(parent) = path.parent().filter(|p| !p.as_os_str().is_empty()) else {
        return Ok(());
    };
    let mut missing = Vec::new();
    let mut folder = parent;
    while !folder.is_dir() {
        missing.push(folder);
        match folder.parent().filter(|p| !p.as_os_str().is_empty()) {
            Some(above) => folder = above,
            None => break,
        }
    }
    for folder in missing.into_iter().rev() {
        let name = folder.file_name().map(|n| n.to_string_lossy());
        if name.is_some_and(|n| n.starts_with(STAGING)) {
            return Err(std::io::Error::new(
                std::io::ErrorKind::NotFound,
                format!("{}: the staging folder is gone", folder.display()),
            ));
        }
        match std::fs::create_dir(folder) {
            Ok(()) => {}
            Err(error) if error.kind() == std::io::ErrorKind::AlreadyExists && folder.is_dir() => {}
            Err(error) => return Err(error),
        }
    }
    Ok(())
}

/// Creates the folders of `relative` inside `root`, never `root` itself: once an interrupt has
/// removed a staging folder, making its subfolders fails instead of bringing it back (which
/// `create_dir_all` would, leaving it behind when the process exits).
fn create_inside(root: &Path, relative: &Path) -> Result<()> {
    let mut path = root.to_path_buf();
    for component in relative.components() {
        path.push(component);
        match std::fs::create_dir(&path) {
            Ok(()) => {}
            Err(error) if error.kind() == std::io::ErrorKind::AlreadyExists && path.is_dir() => {}
            Err(error) => return Err(io(&path)(error)),
        }
    }
    Ok(())
}

/// Creates and removes a file in `dir`: a rename into it will work.
fn probe(dir: &Path, option: &str) -> Result<()> {
    probe_observed(dir, option, |_| {})
}

/// [`probe`], calling `while_present` while the probe file exists. The file is registered like
/// any staging, so an interrupt at any moment removes it.
fn probe_observed(dir: &Path, option: &str, while_present: impl FnOnce(&Path)) -> Result<()> {
    let file = signals::create_registered(
        || {
            tempfile::Builder::new()
                .prefix(&staging_prefix())
                .tempfile_in(dir)
                .map(tempfile::NamedTempFile::into_temp_path)
                .map_err(not_writable(dir, option))
        },
        |file| file.to_path_buf(),
    )?;
    while_present(&file);
    let mut registry = signals::hold();
    signals::unregister(&mut registry, &file);
    file.close().map_err(io(dir))
}

/// Stages a named file beside the file it writes (the named path, or the file a link there leads
/// to: the rename must stay on its file system), which proves that folder writable. The staging
/// file is created as any new file is (0666 less the umask).
fn prepare_file(plan: &FilePlan, created: &mut Vec<PathBuf>) -> Result<StagedFile> {
    let target = crate::named_target(plan)?;
    let parent = match target.parent() {
        Some(parent) if !parent.as_os_str().is_empty() => parent.to_path_buf(),
        _ => PathBuf::from("."),
    };
    create_dir(&parent, &plan.option, created)?;
    remove_dead_staging(&parent);
    let name = target
        .file_name()
        .map(|n| format!("-{}", n.to_string_lossy()))
        .unwrap_or_default();
    let staging = signals::create_registered(
        || {
            tempfile::Builder::new()
                .prefix(&staging_prefix())
                .suffix(&name)
                .permissions(new_file_mode())
                .tempfile_in(&parent)
                .map(tempfile::NamedTempFile::into_temp_path)
                .map_err(not_writable(&plan.path, &plan.option))
        },
        |staging| staging.to_path_buf(),
    )?;
    record_final_name(&staging, &plan.path);
    Ok(StagedFile {
        plan: plan.clone(),
        target,
        staging,
    })
}

/// The mode a new file is created with before the umask, as `std::fs::File::create` does.
pub(crate) fn new_file_mode() -> std::fs::Permissions {
    use std::os::unix::fs::PermissionsExt;
    std::fs::Permissions::from_mode(0o666)
}

/// Removes the staging left in `dir` by processes that no longer run (killed with SIGKILL).
fn remove_dead_staging(dir: &Path) {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    for entry in entries.flatten() {
        let name = entry.file_name().to_string_lossy().into_owned();
        let Some(rest) = name.strip_prefix(STAGING) else {
            continue;
        };
        let pid = rest.split('-').next().and_then(|p| p.parse::<i32>().ok());
        if pid.is_some_and(|pid| !alive(pid)) {
            signals::remove(&entry.path());
        }
    }
}

/// Whether process `pid` exists.
fn alive(pid: i32) -> bool {
    // SAFETY: kill with signal 0 only checks for the process; it has no other effect.
    let result = unsafe { libc::kill(pid, 0) };
    result == 0 || std::io::Error::last_os_error().raw_os_error() != Some(libc::ESRCH)
}

/// The files under `root`, as manifest keys, sorted.
fn staged_files(root: &Path) -> Result<Vec<String>> {
    let mut files = Vec::new();
    let mut pending = vec![root.to_path_buf()];
    while let Some(dir) = pending.pop() {
        for entry in std::fs::read_dir(&dir).map_err(io(&dir))? {
            let path = entry.map_err(io(&dir))?.path();
            if path.is_dir() {
                pending.push(path);
            } else if let Ok(relative) = path.strip_prefix(root) {
                files.push(manifest::key(relative));
            }
        }
    }
    files.sort();
    Ok(files)
}

impl Staged {
    /// The staging folder standing for `folder`: write its planned files here, at the same
    /// relative paths.
    pub fn dir(&self, folder: FolderId) -> &Path {
        self.folders[folder.0].staging.path()
    }

    /// The staging path standing for the named file `file`: write it here.
    pub fn path(&self, file: FileId) -> &Path {
        &self.files[file.0].staging
    }

    /// `message` (an error of a writer given staging paths) in terms of the final paths: see
    /// [`in_final_terms`].
    pub fn in_final_terms(&self, message: &str) -> String {
        in_final_terms(message)
    }

    /// Every staging path of the set.
    fn staging_paths(&self) -> impl Iterator<Item = &Path> {
        let folders = self.folders.iter().map(|f| f.staging.path());
        folders.chain(self.files.iter().map(|f| f.staging.as_ref()))
    }

    /// Moves everything staged into place (see the crate documentation, step 5, and
    /// the `journal` module) and returns the final paths written. Interrupts wait until it is done.
    pub fn commit(mut self) -> Result<Vec<PathBuf>> {
        let mut registry = signals::hold();
        if self.folders.is_empty() {
            return self.commit_named_files_only();
        }
        // Checked and written before anything moves: an error here leaves every folder as it was
        // (dropping the set removes the staging).
        let journals = self.journals()?;
        journal::write_all(&journals)?;
        // Armed: the staging belongs to the journals now, for the next run to finish if this one
        // cannot.
        self.committed = true;
        for folder in &mut self.folders {
            folder.staging.disable_cleanup(true);
            signals::unregister(&mut registry, folder.staging.path());
        }
        for file in &mut self.files {
            file.staging.disable_cleanup(true);
            signals::unregister(&mut registry, &file.staging);
        }
        journal::finish(&journals)?;
        let mut written = Vec::new();
        for (folder, (_, journal)) in self.folders.iter().zip(&journals) {
            let dir = &folder.plan.dir;
            written.extend(journal.moves.iter().map(|key| manifest::path_of(dir, key)));
        }
        written.extend(self.files.iter().map(|file| file.plan.path.clone()));
        Ok(written)
    }

    /// A set of named files only: each moved into place on its own.
    fn commit_named_files_only(&mut self) -> Result<Vec<PathBuf>> {
        let mut written = Vec::new();
        for file in &self.files {
            journal::commit_named(&file.staging, &file.target, &file.plan.option)?;
            written.push(file.plan.path.clone());
        }
        self.committed = true;
        Ok(written)
    }

    /// Every folder's journal (the lead, the first folder, also lists the named files), checked:
    /// nothing staged replaces a foreign file or goes through a link or special file.
    fn journals(&self) -> Result<Vec<(PathBuf, Journal)>> {
        let commit = format!(
            "{}-{}",
            std::process::id(),
            std::time::SystemTime::now()
                .duration_since(std::time::UNIX_EPOCH)
                .map(|since| since.as_nanos())
                .unwrap_or_default()
        );
        let folders: Vec<PathBuf> = self.folders.iter().map(|f| f.resolved.clone()).collect();
        let mut journals = Vec::with_capacity(self.folders.len());
        for folder in &self.folders {
            let mut journal = folder_journal(folder, &self.producer, self.remove_stale)?;
            journal.commit.clone_from(&commit);
            journal.folders.clone_from(&folders);
            journals.push((folder.resolved.clone(), journal));
        }
        for file in &self.files {
            crate::check_named_kind(&file.plan.path, &file.target, &file.plan.option)?;
            let absolute = |path: &Path| std::path::absolute(path).map_err(io(path));
            journals[0].1.files.push(NamedMove {
                staging: absolute(&file.staging)?,
                target: absolute(&file.target)?,
                option: file.plan.option.clone(),
            });
        }
        Ok(journals)
    }
}

/// One folder's part of the commit: every staged file must be planned or at least not foreign,
/// and no path it moves to or removes may go through a link or special file.
fn folder_journal(folder: &StagedFolder, producer: &str, remove_stale: bool) -> Result<Journal> {
    let dir = &folder.plan.dir;
    let moves = staged_files(folder.staging.path())?;
    let old = Manifest::read(dir)?;
    for key in &moves {
        let path = manifest::path_of(dir, key);
        let foreign = old.producer(key).is_none() && folder.plan.existing != Existing::Scratch;
        if foreign && std::fs::symlink_metadata(&path).is_ok() {
            return Err(OutputError::Foreign {
                path,
                manifest: dir.join(manifest::MANIFEST),
                option: folder.plan.option.clone(),
            });
        }
    }
    let removals = if remove_stale {
        old.stale(producer, &moves)
    } else {
        Vec::new()
    };
    for key in moves.iter().chain(&removals) {
        journal::refuse_foreign_component(dir, key, &folder.plan.option)?;
    }
    Ok(Journal {
        commit: String::new(),
        folders: Vec::new(),
        armed: false,
        staging: folder
            .staging
            .path()
            .file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_default(),
        removals,
        manifest: old.updated(producer, &moves, remove_stale),
        moves,
        files: Vec::new(),
    })
}

impl Drop for Staged {
    fn drop(&mut self) {
        // After a commit the registry is already held (and released when `commit` returns).
        let Ok(mut registry) = signals::try_hold() else {
            return;
        };
        for folder in &self.folders {
            signals::unregister(&mut registry, folder.staging.path());
        }
        for file in &self.files {
            signals::unregister(&mut registry, &file.staging);
        }
        if !self.committed {
            // Without a commit nothing of the set stays: staging, then the folders made for it.
            for folder in &self.folders {
                signals::remove(folder.staging.path());
            }
            for file in &self.files {
                signals::remove(&file.staging);
            }
            for dir in self.created.iter().rev() {
                let _ = std::fs::remove_dir(dir);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The writability probe is staging like any other: registered while it exists (an interrupt
    /// then removes it; unregistered, a SIGINT at that moment left it behind), gone afterwards.
    /// Staging subfolders are made inside an existing staging folder only: when an interrupt has
    /// just removed it, making them fails and nothing comes back (with `create_dir_all` the
    /// staging folder reappeared and outlived the process).
    /// A writer's parent folders are made as `create_dir_all` makes them, except a staging folder:
    /// after an interrupt removed it, writing into it fails and it stays removed.
    #[test]
    fn a_writers_folders_never_bring_back_a_removed_staging() {
        let dir = tempfile::tempdir().unwrap();
        let plain = dir.path().join("a/b/c.md");
        create_parent_folders(&plain).unwrap();
        assert!(dir.path().join("a/b").is_dir());
        let staging = dir.path().join(".learn-staging-1-x");
        std::fs::create_dir(&staging).unwrap();
        create_parent_folders(&staging.join("tables/t.md")).unwrap();
        assert!(staging.join("tables").is_dir());
        signals::remove(&staging);
        let error = create_parent_folders(&staging.join("tables/t.md")).unwrap_err();
        assert_eq!(error.kind(), std::io::ErrorKind::NotFound);
        assert!(!staging.exists(), "the removed staging stays removed");
    }

    #[test]
    fn subfolders_do_not_bring_back_a_removed_staging() {
        let dir = tempfile::tempdir().unwrap();
        let staging = dir.path().join(".learn-staging-1-x");
        std::fs::create_dir(&staging).unwrap();
        create_inside(&staging, Path::new("figures/svg")).unwrap();
        create_inside(&staging, Path::new("figures")).unwrap();
        assert!(staging.join("figures/svg").is_dir());
        signals::remove(&staging);
        assert!(create_inside(&staging, Path::new("figures/svg")).is_err());
        assert!(!staging.exists(), "the removed staging stays removed");
    }

    #[test]
    fn the_probe_is_registered_while_it_exists() {
        let dir = tempfile::tempdir().unwrap();
        let mut seen = None;
        probe_observed(dir.path(), "--out", |file| {
            assert!(file.exists());
            assert!(signals::hold().iter().any(|p| p == file), "registered");
            seen = Some(file.to_path_buf());
        })
        .unwrap();
        let file = seen.expect("the probe ran");
        assert!(!file.exists(), "removed");
        assert!(!signals::hold().contains(&file), "unregistered");
    }
}
