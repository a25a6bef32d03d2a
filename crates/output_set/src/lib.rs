//! The one home for writing a command's results safely. Every `learn` command that writes files
//! goes through an [`OutputSet`]:
//!
//! 1. **plan**: the folders it writes into (with the files it will put there, relative to each)
//!    and the single files the user named, and every file the run reads;
//! 2. **check** ([`OutputSet::check`], no side effects): no output is an input (whatever the
//!    spelling of either path), nor the folder of another output, each can be a file or folder,
//!    and an existing file is replaced only
//!    when allowed: in a folder only a file `learn` wrote there itself (its manifest says so), and
//!    then only with [`Existing::Replace`] (`--force`, or the tool's scratch); a named file only
//!    with `--force`, and only a regular file (a link is written through); below a folder, only
//!    folders and regular files (never through a link);
//! 3. **prepare** ([`OutputSet::prepare`]), before any work: each folder is created and locked (a
//!    second run into it is refused), and a staging folder (`.learn-staging-<pid>-*`) is made in
//!    it, which proves it writable; every subfolder of a planned file gets a probe file;
//! 4. the work writes into the staging paths ([`Staged::dir`], [`Staged::path`]);
//! 5. **commit** ([`Staged::commit`]): a journal in every folder of the set first (if one cannot be
//!    written, the others are withdrawn and nothing moves), the first folder's armed last, then
//!    per folder the renames into place, stale own files removed, the manifest
//!    (`.learn-outputs.json`) rewritten, then the named files. An interrupt (SIGINT, SIGTERM) or a
//!    failure before the commit removes the staging and leaves the old set as it was; SIGKILL
//!    leaves a hidden staging folder that the next run into the folder removes, and journals that
//!    the next run into any folder of the set finishes or undoes in all of them
//!    (the `journal` module).
//!
//! What it is not: a writer of formats (callers write their JSON, SVG or CSV into the staging
//! paths), nor a checker of what is read (see the `bounded_read` crate). The protocol, and why, is in
//! `docs/data-safety.md`.

mod error;
mod journal;
pub mod manifest;
pub mod paths;
mod signals;
mod stage;
mod test_hooks;

use std::path::{Path, PathBuf};

pub use error::{OutputError, Result};
pub use manifest::{MANIFEST, Manifest};
pub use signals::wait_if_interrupted;
pub use stage::{Staged, create_parent_folders, in_final_terms};

use paths::FileKind;

/// What may happen to an output file that already exists.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Existing {
    /// Refuse to replace it (the default; `--force` lifts it).
    Refuse,
    /// Replace it (`--force`). A foreign file in a folder is still never replaced.
    Replace,
    /// The folder is the tool's own git-ignored scratch (e.g. `results/.scratch/learn`): every
    /// file in it may be replaced, recorded or not. Never for a path the user named.
    Scratch,
}

impl Existing {
    /// [`Existing::Replace`] when `--force` was given.
    pub fn from_force(force: bool) -> Self {
        if force { Self::Replace } else { Self::Refuse }
    }
}

/// A folder of the set, as returned by [`OutputSet::folder`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct FolderId(usize);

/// A named file of the set, as returned by [`OutputSet::file`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct FileId(usize);

#[derive(Clone, Debug)]
pub(crate) struct FolderPlan {
    pub dir: PathBuf,
    pub option: String,
    pub existing: Existing,
    /// Planned files, relative to `dir`.
    pub files: Vec<PathBuf>,
    /// Subfolders (relative) that files whose names are known only after the work go into.
    pub subfolders: Vec<PathBuf>,
}

#[derive(Clone, Debug)]
pub(crate) struct FilePlan {
    pub path: PathBuf,
    pub option: String,
    pub existing: Existing,
}

/// The outputs of one run, planned before any work. See the crate documentation.
#[derive(Clone, Debug)]
pub struct OutputSet {
    producer: String,
    /// Whether the producer's earlier files that it does not write again are removed.
    remove_stale: bool,
    folders: Vec<FolderPlan>,
    files: Vec<FilePlan>,
    inputs: Vec<(String, PathBuf)>,
}

impl OutputSet {
    /// An empty set for `producer`: what the manifest records as the writer (e.g. `reproduce`);
    /// its earlier files in a folder that it no longer writes are removed on commit.
    pub fn new(producer: impl Into<String>) -> Self {
        Self {
            producer: producer.into(),
            remove_stale: true,
            folders: Vec::new(),
            files: Vec::new(),
            inputs: Vec::new(),
        }
    }

    /// This set rewrites some of the producer's files and keeps its others (e.g. a report
    /// rendered again from the run's data): nothing is removed on commit.
    pub fn updating_only_its_files(mut self) -> Self {
        self.remove_stale = false;
        self
    }

    /// A file the run reads (`what` names it in errors, e.g. "the --config input"): no output
    /// may be it.
    pub fn input(&mut self, what: impl Into<String>, path: impl Into<PathBuf>) -> &mut Self {
        self.inputs.push((what.into(), path.into()));
        self
    }

    /// A folder the run writes into, given by `option`. The same folder named twice (however
    /// spelt) is one folder.
    pub fn folder(
        &mut self,
        dir: impl Into<PathBuf>,
        option: &str,
        existing: Existing,
    ) -> FolderId {
        let dir = dir.into();
        if let Some(index) = self
            .folders
            .iter()
            .position(|f| paths::same_file(&f.dir, &dir))
        {
            return FolderId(index);
        }
        self.folders.push(FolderPlan {
            dir,
            option: option.to_string(),
            existing,
            files: Vec::new(),
            subfolders: Vec::new(),
        });
        FolderId(self.folders.len() - 1)
    }

    /// Plans the subfolder `relative` of `folder` for files whose names are known only after the
    /// work (checked when committed: one that would replace a foreign file fails the commit, and
    /// the old set stays).
    pub fn subfolder_in(&mut self, folder: FolderId, relative: impl Into<PathBuf>) {
        let relative = relative.into();
        let plan = &mut self.folders[folder.0];
        if !plan.subfolders.contains(&relative) {
            plan.subfolders.push(relative);
        }
    }

    /// Plans `relative` (e.g. `tables/full.json`) in `folder`; returns its final path.
    pub fn file_in(&mut self, folder: FolderId, relative: impl Into<PathBuf>) -> PathBuf {
        let relative = relative.into();
        let plan = &mut self.folders[folder.0];
        let path = plan.dir.join(&relative);
        if !plan.files.contains(&relative) {
            plan.files.push(relative);
        }
        path
    }

    /// A single file the user named with `option` (e.g. `sindy --out model.json`).
    pub fn file(&mut self, path: impl Into<PathBuf>, option: &str, existing: Existing) -> FileId {
        self.files.push(FilePlan {
            path: path.into(),
            option: option.to_string(),
            existing,
        });
        FileId(self.files.len() - 1)
    }

    /// Every final path the set writes: the planned files of each folder, then the named files.
    pub fn targets(&self) -> Vec<PathBuf> {
        self.targets_with_options()
            .into_iter()
            .map(|(path, _)| path)
            .collect()
    }

    /// [`OutputSet::targets`], each with the option that places it.
    fn targets_with_options(&self) -> Vec<(PathBuf, &str)> {
        let in_folders = self
            .folders
            .iter()
            .flat_map(|f| f.files.iter().map(|r| (f.dir.join(r), f.option.as_str())));
        in_folders
            .chain(
                self.files
                    .iter()
                    .map(|f| (f.path.clone(), f.option.as_str())),
            )
            .collect()
    }

    /// Checks the plan without touching the disk: see the crate documentation (step 2).
    pub fn check(&self) -> Result<()> {
        for target in self.targets() {
            self.refuse_input(&target)?;
        }
        self.refuse_file_as_folder()?;
        for folder in &self.folders {
            check_folder(folder, &self.producer, self.remove_stale, &self.inputs)?;
        }
        for file in &self.files {
            check_named_file(file)?;
        }
        Ok(())
    }

    /// Checks, then locks and stages every folder and file: see the crate documentation (step 3).
    pub fn prepare(self) -> Result<Staged> {
        self.check()?;
        stage::prepare(self)
    }

    /// Fails if an output is also a folder another output goes into (e.g. a file of one option
    /// that is a subfolder of another's), whatever the spelling: it cannot be both. Only folders
    /// that do not exist yet are compared (an existing one is refused as a file to write, and a
    /// file below an existing file as below a non-directory).
    fn refuse_file_as_folder(&self) -> Result<()> {
        let targets = self.targets_with_options();
        let places: std::collections::HashMap<PathBuf, usize> = targets
            .iter()
            .enumerate()
            .filter_map(|(index, (path, _))| Some((paths::resolved(path)?, index)))
            .collect();
        let mut seen = std::collections::HashSet::new();
        for (inner, inner_option) in &targets {
            let new_folders = inner
                .ancestors()
                .skip(1)
                .take_while(|a| !a.as_os_str().is_empty() && std::fs::symlink_metadata(a).is_err());
            for folder in new_folders {
                if !seen.insert(folder.to_path_buf()) {
                    break;
                }
                let found = paths::resolved(folder).and_then(|place| places.get(&place));
                if let Some(&index) = found {
                    let (path, option) = &targets[index];
                    return Err(OutputError::FileIsFolderOfAnother {
                        path: path.clone(),
                        option: option.to_string(),
                        inner: inner.clone(),
                        inner_option: inner_option.to_string(),
                    });
                }
            }
        }
        Ok(())
    }

    fn refuse_input(&self, target: &Path) -> Result<()> {
        match self
            .inputs
            .iter()
            .find(|(_, input)| paths::same_file(target, input))
        {
            Some((what, _)) => Err(OutputError::OutputIsInput {
                path: target.to_path_buf(),
                what: what.clone(),
            }),
            None => Ok(()),
        }
    }
}

/// A folder's checks: it can be a folder; each planned file can be a file and, if it exists, was
/// written by `learn` and may be replaced; no stale own file it would remove is an input.
fn check_folder(
    folder: &FolderPlan,
    producer: &str,
    remove_stale: bool,
    inputs: &[(String, PathBuf)],
) -> Result<()> {
    let option = folder.option.clone();
    if folder.dir.as_os_str().is_empty() {
        return Err(OutputError::EmptyPath { option });
    }
    if folder.dir.exists() && !folder.dir.is_dir() {
        return Err(OutputError::FolderIsFile {
            path: folder.dir.clone(),
            option,
        });
    }
    if let Some(parent) = paths::non_directory_ancestor(&folder.dir) {
        return Err(OutputError::BelowNonDirectory {
            path: folder.dir.clone(),
            parent: parent.to_path_buf(),
            option,
        });
    }
    let manifest = if folder.dir.is_dir() {
        Manifest::read(&folder.dir)?
    } else {
        Manifest::default()
    };
    for relative in &folder.files {
        check_folder_file(folder, &manifest, relative)?;
    }
    for relative in &folder.subfolders {
        stage::refuse_foreign_folder(&folder.dir, relative, &option)?;
    }
    let planned: Vec<String> = folder.files.iter().map(|r| manifest::key(r)).collect();
    let stale = if remove_stale {
        manifest.stale(producer, &planned)
    } else {
        Vec::new()
    };
    for stale in stale {
        let path = manifest::path_of(&folder.dir, &stale);
        if let Some((what, _)) = inputs.iter().find(|(_, i)| paths::same_file(&path, i)) {
            return Err(OutputError::OutputIsInput {
                path,
                what: format!("{what} (an earlier output of this command, removed on commit)"),
            });
        }
    }
    Ok(())
}

/// One planned file of a folder: see [`check_folder`].
fn check_folder_file(folder: &FolderPlan, manifest: &Manifest, relative: &Path) -> Result<()> {
    let path = folder.dir.join(relative);
    let option = folder.option.clone();
    if path.is_dir() {
        return Err(OutputError::FileIsDirectory { path, option });
    }
    if let Some(parent) = paths::non_directory_ancestor(&path) {
        return Err(OutputError::BelowNonDirectory {
            parent: parent.to_path_buf(),
            path,
            option,
        });
    }
    journal::refuse_foreign_component(&folder.dir, &manifest::key(relative), &option)?;
    if std::fs::symlink_metadata(&path).is_err() || folder.existing == Existing::Scratch {
        return Ok(());
    }
    match manifest.producer(&manifest::key(relative)) {
        None => Err(OutputError::Foreign {
            manifest: folder.dir.join(MANIFEST),
            path,
            option,
        }),
        Some(producer) if folder.existing == Existing::Refuse => Err(OutputError::OwnExists {
            path,
            producer: producer.to_string(),
        }),
        Some(_) => Ok(()),
    }
}

/// A named file's checks: it can be a file; what is there (through links) is a regular file, and
/// an existing one is replaced only with `--force`.
fn check_named_file(file: &FilePlan) -> Result<()> {
    let option = file.option.clone();
    if file.path.as_os_str().is_empty() {
        return Err(OutputError::EmptyPath { option });
    }
    if file.path.is_dir() {
        return Err(OutputError::FileIsDirectory {
            path: file.path.clone(),
            option,
        });
    }
    if let Some(parent) = paths::non_directory_ancestor(&file.path) {
        return Err(OutputError::BelowNonDirectory {
            path: file.path.clone(),
            parent: parent.to_path_buf(),
            option,
        });
    }
    let target = named_target(file)?;
    check_named_kind(&file.path, &target, &option)?;
    if file.existing == Existing::Refuse && std::fs::symlink_metadata(&file.path).is_ok() {
        return Err(OutputError::Exists {
            path: file.path.clone(),
        });
    }
    Ok(())
}

/// The file a named output writes: the path named, or, when it is a symbolic link, the file the
/// link leads to (the link itself is never replaced). A link to nothing is refused.
pub(crate) fn named_target(file: &FilePlan) -> Result<PathBuf> {
    let is_link = std::fs::symlink_metadata(&file.path).is_ok_and(|m| m.file_type().is_symlink());
    if !is_link {
        return Ok(file.path.clone());
    }
    file.path
        .canonicalize()
        .map_err(|_| OutputError::LinkToNothing {
            path: file.path.clone(),
            target: std::fs::read_link(&file.path).unwrap_or_default(),
            option: file.option.clone(),
        })
}

/// An error when `target` (the file the named output `named` writes, links resolved) exists and
/// is not a regular file: a FIFO, device or socket is never written to nor replaced, with or
/// without `--force`.
pub(crate) fn check_named_kind(named: &Path, target: &Path, option: &str) -> Result<()> {
    match FileKind::of_path(target) {
        None | Some(FileKind::Regular) => Ok(()),
        Some(FileKind::Directory) => Err(OutputError::FileIsDirectory {
            path: named.to_path_buf(),
            option: option.to_string(),
        }),
        Some(kind) => Err(OutputError::NotRegularFile {
            path: named.to_path_buf(),
            kind,
            option: option.to_string(),
        }),
    }
}
