//! Preparing a checked [`OutputSet`] (lock, probe, stage) and committing it (journal, renames,
//! manifest).

use std::fs::File;
use std::path::{Path, PathBuf};

use fs4::FileExt;
use serde::{Deserialize, Serialize};
use tempfile::{TempDir, TempPath};

use crate::error::{OutputError, Result, io};
use crate::manifest::{self, Manifest, write_atomically};
use crate::{Existing, FileId, FilePlan, FolderId, FolderPlan, OutputSet, signals};

/// The journal of a commit in progress, in the output folder.
const JOURNAL: &str = ".learn-commit.json";
/// Every staging name starts so (hidden; ignored by git; removed by the next run).
const STAGING: &str = ".learn-staging-";

/// The prefix of this process's staging names: `.learn-staging-<pid>-`.
pub(crate) fn staging_prefix() -> String {
    format!("{STAGING}{}-", std::process::id())
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
    /// The open folder, locked while the set lives.
    _lock: File,
    staging: TempDir,
}

#[derive(Debug)]
struct StagedFile {
    plan: FilePlan,
    staging: TempPath,
}

/// What a commit does in one folder, written before it starts so that a killed commit is finished
/// by the next run into the folder.
#[derive(Serialize, Deserialize)]
struct Journal {
    staging: String,
    moves: Vec<String>,
    removals: Vec<String>,
    manifest: Manifest,
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
    for plan in &set.folders {
        let folder = prepare_folder(plan, &mut staged.created)?;
        staged.folders.push(folder);
    }
    // Under the locks: what another run may have committed meanwhile is checked again.
    set.check()?;
    for plan in &set.files {
        let file = prepare_file(plan, &mut staged.created)?;
        staged.files.push(file);
    }
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

/// Creates and locks the folder, finishes a killed commit, removes dead staging, stages and
/// probes every subfolder of a planned file.
fn prepare_folder(plan: &FolderPlan, created: &mut Vec<PathBuf>) -> Result<StagedFolder> {
    let dir = &plan.dir;
    create_dir(dir, &plan.option, created)?;
    let lock = File::open(dir).map_err(not_writable(dir, &plan.option))?;
    if FileExt::try_lock(&lock).is_err() {
        return Err(OutputError::Locked {
            dir: dir.clone(),
            option: plan.option.clone(),
        });
    }
    {
        // A killed commit is finished whole: an interrupt waits for it, as for any commit.
        let _registry = signals::hold_installed();
        finish_journal(dir)?;
    }
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
    let parents = plan.files.iter().filter_map(|r| r.parent());
    for parent in parents.chain(plan.subfolders.iter().map(PathBuf::as_path)) {
        if parent.as_os_str().is_empty() {
            continue;
        }
        let target = dir.join(parent);
        create_dir(&target, &plan.option, created)?;
        // A run killed while it probed this subfolder left its probe here.
        remove_dead_staging(&target);
        probe(&target, &plan.option)?;
        create_inside(staging.path(), parent)?;
    }
    Ok(StagedFolder {
        plan: plan.clone(),
        _lock: lock,
        staging,
    })
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

/// Stages a named file beside its target (which proves the folder writable).
fn prepare_file(plan: &FilePlan, created: &mut Vec<PathBuf>) -> Result<StagedFile> {
    let parent = match plan.path.parent() {
        Some(parent) if !parent.as_os_str().is_empty() => parent.to_path_buf(),
        _ => PathBuf::from("."),
    };
    create_dir(&parent, &plan.option, created)?;
    remove_dead_staging(&parent);
    let name = plan
        .path
        .file_name()
        .map(|n| format!("-{}", n.to_string_lossy()))
        .unwrap_or_default();
    let staging = signals::create_registered(
        || {
            tempfile::Builder::new()
                .prefix(&staging_prefix())
                .suffix(&name)
                .tempfile_in(&parent)
                .map(tempfile::NamedTempFile::into_temp_path)
                .map_err(not_writable(&plan.path, &plan.option))
        },
        |staging| staging.to_path_buf(),
    )?;
    Ok(StagedFile {
        plan: plan.clone(),
        staging,
    })
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

/// Finishes a commit that was killed in `dir` (its journal is still there): the remaining moves,
/// the removals, the manifest.
fn finish_journal(dir: &Path) -> Result<()> {
    let path = dir.join(JOURNAL);
    let Ok(text) = std::fs::read_to_string(&path) else {
        return Ok(());
    };
    let journal: Journal = serde_json::from_str(&text).map_err(|error| OutputError::Manifest {
        path: path.clone(),
        message: format!("not a learn commit journal ({error}); move it away"),
    })?;
    apply(dir, &journal)
}

/// Carries out a journal: idempotent (a move whose source is gone was done).
fn apply(dir: &Path, journal: &Journal) -> Result<()> {
    let staging = dir.join(&journal.staging);
    for key in &journal.moves {
        let from = manifest::path_of(&staging, key);
        let to = manifest::path_of(dir, key);
        if std::fs::symlink_metadata(&from).is_err() {
            continue;
        }
        if let Some(parent) = to.parent() {
            std::fs::create_dir_all(parent).map_err(io(parent))?;
        }
        std::fs::rename(&from, &to).map_err(io(&to))?;
    }
    for key in &journal.removals {
        let path = manifest::path_of(dir, key);
        match std::fs::remove_file(&path) {
            Err(error) if error.kind() != std::io::ErrorKind::NotFound => {
                return Err(io(&path)(error));
            }
            _ => {}
        }
    }
    journal.manifest.write(dir)?;
    let journal_path = dir.join(JOURNAL);
    std::fs::remove_file(&journal_path).map_err(io(&journal_path))?;
    signals::remove(&staging);
    Ok(())
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

    /// `message` (an error of a writer given staging paths) in terms of the final paths: every
    /// staging path replaced by what it stands for.
    pub fn in_final_terms(&self, message: &str) -> String {
        let mut text = message.to_string();
        for file in &self.files {
            text = text.replace(
                &file.staging.display().to_string(),
                &file.plan.path.display().to_string(),
            );
        }
        for folder in &self.folders {
            text = text.replace(
                &folder.staging.path().display().to_string(),
                &folder.plan.dir.display().to_string(),
            );
        }
        text
    }

    /// Moves everything staged into place (see the crate documentation, step 5) and returns the
    /// final paths written. Interrupts wait until it is done.
    pub fn commit(mut self) -> Result<Vec<PathBuf>> {
        self.committed = true;
        let mut registry = signals::hold();
        // Every folder's journal first, then the moves: a run killed during the moves leaves a
        // journal in every folder of the set, and the next run into them completes all of them.
        let mut journals = Vec::with_capacity(self.folders.len());
        for folder in &self.folders {
            match write_journal(folder, &self.producer, self.remove_stale) {
                Ok(journal) => journals.push(journal),
                Err(error) => {
                    // Nothing has moved yet: withdrawing the journals leaves every folder as it was.
                    for done in &self.folders[..journals.len()] {
                        let _ = std::fs::remove_file(done.plan.dir.join(JOURNAL));
                    }
                    self.committed = false;
                    return Err(error);
                }
            }
        }
        let mut written = Vec::new();
        for (folder, journal) in self.folders.iter().zip(&journals) {
            let dir = &folder.plan.dir;
            apply(dir, journal)?;
            written.extend(journal.moves.iter().map(|key| manifest::path_of(dir, key)));
            signals::unregister(&mut registry, folder.staging.path());
        }
        for file in std::mem::take(&mut self.files) {
            let StagedFile { plan, staging } = file;
            signals::unregister(&mut registry, &staging);
            staging
                .persist(&plan.path)
                .map_err(|error| io(&plan.path)(error.error))?;
            written.push(plan.path);
        }
        Ok(written)
    }
}

/// One folder's commit journal, written: every staged file must be planned or at least not
/// foreign.
fn write_journal(folder: &StagedFolder, producer: &str, remove_stale: bool) -> Result<Journal> {
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
    let journal = Journal {
        staging: folder
            .staging
            .path()
            .file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_default(),
        removals: if remove_stale {
            old.stale(producer, &moves)
        } else {
            Vec::new()
        },
        manifest: old.updated(producer, &moves, remove_stale),
        moves,
    };
    let text = serde_json::to_string(&journal).map_err(|error| OutputError::Manifest {
        path: dir.join(JOURNAL),
        message: error.to_string(),
    })?;
    write_atomically(&dir.join(JOURNAL), &text)?;
    Ok(journal)
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
