//! The commit journals: what a commit does in each folder of its set, written before anything
//! moves, so that a commit killed at any instant is finished or undone whole by the next run into
//! any of its folders.
//!
//! The protocol. Every folder's journal carries the commit's id and the list of the set's folders;
//! the first folder is the lead. The journals are written lead first, unarmed; then the lead's is
//! rewritten armed (one atomic rename: the commit point); then every folder's files are moved and
//! its manifest written; then the other journals are removed, the lead's last. So a journal whose
//! lead journal is unarmed belongs to a commit that moved nothing (undone), one whose lead journal
//! is armed to a commit to finish, and a lead journal cannot be missing while another is there.

use std::fs::{File, Metadata};
use std::path::{Path, PathBuf};

use fs4::FileExt;
use serde::{Deserialize, Serialize};

use crate::error::{OutputError, Result, io};
use crate::manifest::{self, Manifest, write_atomically};
use crate::paths::{self, FileKind, Leaf};
use crate::{signals, test_hooks};

/// The journal of a commit in progress, in each output folder of the set.
pub(crate) const JOURNAL: &str = ".learn-commit.json";

/// One folder's part of a commit.
#[derive(Clone, Serialize, Deserialize)]
pub(crate) struct Journal {
    /// The id every journal of the commit shares (empty in a journal of a single folder written
    /// before journals had one: it is finished alone).
    #[serde(default)]
    pub commit: String,
    /// Every folder of the set, absolute, the lead first.
    #[serde(default)]
    pub folders: Vec<PathBuf>,
    /// In the lead's journal: the commit is decided and is finished by whoever finds it.
    #[serde(default)]
    pub armed: bool,
    /// The staging folder's name in this folder.
    pub staging: String,
    pub moves: Vec<String>,
    pub removals: Vec<String>,
    pub manifest: Manifest,
    /// In the lead's journal: the named files of the set (their staging, beside each target).
    #[serde(default)]
    pub files: Vec<NamedMove>,
}

/// A named file's move: its staging file onto the (resolved) target.
#[derive(Clone, Serialize, Deserialize)]
pub(crate) struct NamedMove {
    pub staging: PathBuf,
    pub target: PathBuf,
    /// The option that named it, for errors.
    pub option: String,
}

/// The journal in `dir`, if there is one.
fn read(dir: &Path) -> Result<Option<Journal>> {
    let path = dir.join(JOURNAL);
    let text = match std::fs::read_to_string(&path) {
        Ok(text) => text,
        Err(error) if error.kind() == std::io::ErrorKind::NotFound => return Ok(None),
        Err(error) => return Err(io(&path)(error)),
    };
    serde_json::from_str(&text)
        .map(Some)
        .map_err(|error| OutputError::Manifest {
            path,
            message: format!("not a learn commit journal ({error}); move it away"),
        })
}

fn write(dir: &Path, journal: &Journal) -> Result<()> {
    let path = dir.join(JOURNAL);
    let text = serde_json::to_string(journal).map_err(|error| OutputError::Manifest {
        path: path.clone(),
        message: error.to_string(),
    })?;
    write_atomically(&path, &text)
}

fn remove(dir: &Path) -> Result<()> {
    let path = dir.join(JOURNAL);
    match std::fs::remove_file(&path) {
        Err(error) if error.kind() != std::io::ErrorKind::NotFound => Err(io(&path)(error)),
        _ => Ok(()),
    }
}

/// Writes every folder's journal (`journals`, the lead first), then arms the lead's. On an error
/// nothing has moved: the journals written are withdrawn and the error returned.
pub(crate) fn write_all(journals: &[(PathBuf, Journal)]) -> Result<()> {
    let single = journals.len() == 1;
    for (index, (dir, journal)) in journals.iter().enumerate() {
        let written = write(
            dir,
            &Journal {
                armed: single,
                ..journal.clone()
            },
        );
        if let Err(error) = written {
            withdraw(&journals[..index]);
            return Err(error);
        }
        test_hooks::point(format_args!("journal {index} written"), &[]);
    }
    if !single {
        let (lead, journal) = &journals[0];
        let armed = write(
            lead,
            &Journal {
                armed: true,
                ..journal.clone()
            },
        );
        if let Err(error) = armed {
            withdraw(journals);
            return Err(error);
        }
        test_hooks::point(format_args!("armed"), &[]);
    }
    Ok(())
}

/// Removes the journals of a commit that moved nothing, the lead's last.
fn withdraw(journals: &[(PathBuf, Journal)]) {
    for (dir, _) in journals.iter().rev() {
        let _ = remove(dir);
    }
}

/// Carries out an armed commit (`journals`: those still present, the lead first): every folder's
/// moves, removals and manifest, the named files, then the journals (the lead's last) and the
/// staging. Idempotent: a move whose staging file is gone was done.
pub(crate) fn finish(journals: &[(PathBuf, Journal)]) -> Result<()> {
    for (index, (dir, journal)) in journals.iter().enumerate() {
        apply_folder(dir, journal, index)?;
    }
    if let Some((_, lead)) = journals.first() {
        for (index, named) in lead.files.iter().enumerate() {
            if std::fs::symlink_metadata(&named.staging).is_ok() {
                commit_named(&named.staging, &named.target, &named.option)?;
            }
            test_hooks::point(format_args!("named file {index} moved"), &[]);
        }
    }
    for (index, (dir, journal)) in journals.iter().enumerate().rev() {
        remove(dir)?;
        signals::remove(&dir.join(&journal.staging));
        test_hooks::point(format_args!("journal {index} removed"), &[]);
    }
    Ok(())
}

/// One folder's moves, removals and manifest. Every path is checked first to be what `learn`
/// makes (folders, regular files), never a link or special file put there since.
fn apply_folder(dir: &Path, journal: &Journal, index: usize) -> Result<()> {
    let staging = dir.join(&journal.staging);
    for (number, key) in journal.moves.iter().enumerate() {
        let from = manifest::path_of(&staging, key);
        if std::fs::symlink_metadata(&from).is_err() {
            continue;
        }
        refuse_foreign_component(dir, key, "a commit to finish")?;
        let to = manifest::path_of(dir, key);
        if let Some(parent) = to.parent() {
            std::fs::create_dir_all(parent).map_err(io(parent))?;
        }
        if let Ok(existing) = std::fs::symlink_metadata(&to) {
            keep_mode_and_owner(&from, &existing)?;
        }
        std::fs::rename(&from, &to).map_err(io(&to))?;
        if number == 0 {
            test_hooks::point(format_args!("folder {index}: first file moved"), &[]);
        }
    }
    test_hooks::point(format_args!("folder {index}: files moved"), &[]);
    for key in &journal.removals {
        refuse_foreign_component(dir, key, "a commit to finish")?;
        let path = manifest::path_of(dir, key);
        match std::fs::remove_file(&path) {
            Err(error) if error.kind() != std::io::ErrorKind::NotFound => {
                return Err(io(&path)(error));
            }
            _ => {}
        }
    }
    journal.manifest.write(dir)?;
    test_hooks::point(format_args!("folder {index}: manifest written"), &[]);
    Ok(())
}

/// An error when a component of `key` below `dir` is not what `learn` makes there.
pub(crate) fn refuse_foreign_component(dir: &Path, key: &str, option: &str) -> Result<()> {
    let relative = manifest::path_of(Path::new(""), key);
    match paths::first_foreign_component(dir, &relative, Leaf::File) {
        Some((path, kind)) => Err(OutputError::NotMadeByLearn {
            expected: if path == dir.join(&relative) {
                Leaf::File
            } else {
                Leaf::Folder
            },
            path,
            kind,
            option: option.to_string(),
        }),
        None => Ok(()),
    }
}

/// Gives the staged file `staged` the permission bits, and (where the process may) the owner and
/// group, of the `existing` file it replaces.
pub(crate) fn keep_mode_and_owner(staged: &Path, existing: &Metadata) -> Result<()> {
    use std::os::unix::fs::{MetadataExt, PermissionsExt};
    let mode = std::fs::Permissions::from_mode(existing.mode() & 0o777);
    std::fs::set_permissions(staged, mode).map_err(io(staged))?;
    let current = std::fs::symlink_metadata(staged).map_err(io(staged))?;
    if (current.uid(), current.gid()) != (existing.uid(), existing.gid()) {
        // Only root may give a file away: otherwise the new file stays the writer's.
        let _ = std::os::unix::fs::chown(staged, Some(existing.uid()), Some(existing.gid()));
    }
    Ok(())
}

/// Moves a named file's staging onto its target (a link already resolved): a new file is
/// renamed into place; an existing regular file is replaced by rename with its mode and owner
/// kept, or, when it has other hard links (which a rename would leave with the old text),
/// rewritten through its inode; anything else is refused.
pub(crate) fn commit_named(staging: &Path, target: &Path, option: &str) -> Result<()> {
    use std::os::unix::fs::MetadataExt;
    let existing = match std::fs::symlink_metadata(target) {
        Ok(existing) => existing,
        Err(error) if error.kind() == std::io::ErrorKind::NotFound => {
            return std::fs::rename(staging, target).map_err(io(target));
        }
        Err(error) => return Err(io(target)(error)),
    };
    let kind = FileKind::of(&existing);
    if kind != FileKind::Regular {
        return Err(OutputError::NotRegularFile {
            path: target.to_path_buf(),
            kind,
            option: option.to_string(),
        });
    }
    if existing.nlink() > 1 {
        write_through(staging, target)?;
        return std::fs::remove_file(staging).map_err(io(staging));
    }
    keep_mode_and_owner(staging, &existing)?;
    std::fs::rename(staging, target).map_err(io(target))
}

/// Copies `staging` into the regular file `target`'s own inode (opened without following a link,
/// without blocking on a FIFO put there since; checked regular once open).
fn write_through(staging: &Path, target: &Path) -> Result<()> {
    use std::os::unix::fs::OpenOptionsExt;
    let mut file = std::fs::OpenOptions::new()
        .write(true)
        .custom_flags(libc::O_NOFOLLOW | libc::O_NONBLOCK)
        .open(target)
        .map_err(io(target))?;
    let metadata = file.metadata().map_err(io(target))?;
    if !metadata.is_file() {
        return Err(OutputError::NotRegularFile {
            path: target.to_path_buf(),
            kind: FileKind::of(&metadata),
            option: String::from("a named output"),
        });
    }
    let mut source = File::open(staging).map_err(io(staging))?;
    let length = std::io::copy(&mut source, &mut file).map_err(io(target))?;
    file.set_len(length).map_err(io(target))?;
    file.sync_all().map_err(io(target))
}

/// Finishes or undoes a commit interrupted in `dir` (its journal is there), in every folder of
/// its set; `held` are the folders this run has locked. See the module documentation.
pub(crate) fn recover(dir: &Path, held: &[PathBuf]) -> Result<()> {
    let Some(journal) = read(dir)? else {
        return Ok(());
    };
    if journal.folders.is_empty() {
        return finish(&[(dir.to_path_buf(), journal)]);
    }
    let _locks = lock_others(&journal.folders, held)?;
    let lead = &journal.folders[0];
    let lead_journal = read(lead)
        .ok()
        .flatten()
        .filter(|lead| lead.commit == journal.commit);
    let Some(lead_journal) = lead_journal else {
        return Err(OutputError::UnresolvableCommit {
            journal: dir.join(JOURNAL),
            lead: lead.clone(),
        });
    };
    let mut journals = vec![(lead.clone(), lead_journal.clone())];
    for folder in &journal.folders[1..] {
        if let Some(other) = read(folder)?.filter(|other| other.commit == journal.commit) {
            journals.push((folder.clone(), other));
        }
    }
    if lead_journal.armed {
        return finish(&journals);
    }
    for named in &lead_journal.files {
        signals::remove(&named.staging);
    }
    for (folder, other) in journals.iter().rev() {
        signals::remove(&folder.join(&other.staging));
        remove(folder)?;
    }
    Ok(())
}

/// Locks the folders of an interrupted commit that this run does not hold already (a run into
/// one of them is refused meanwhile); a folder that is gone is skipped.
fn lock_others(folders: &[PathBuf], held: &[PathBuf]) -> Result<Vec<File>> {
    let mut locks = Vec::new();
    for folder in folders {
        if held.iter().any(|dir| paths::same_file(dir, folder)) {
            continue;
        }
        let Ok(lock) = File::open(folder) else {
            continue;
        };
        if FileExt::try_lock(&lock).is_err() {
            return Err(OutputError::Locked {
                dir: folder.clone(),
                option: String::from("a folder of an interrupted commit to finish"),
            });
        }
        locks.push(lock);
    }
    Ok(locks)
}
