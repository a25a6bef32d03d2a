//! Why an output set could not be planned, prepared or committed: each message names the path and
//! the option that placed it, on one line.

use std::path::PathBuf;

use crate::paths::{FileKind, Leaf};

/// An output set refused or failed.
#[derive(Debug, thiserror::Error)]
pub enum OutputError {
    #[error(
        "{}: is {what}, which this run reads: refusing to write over it (even with --force)",
        path.display()
    )]
    OutputIsInput { path: PathBuf, what: String },
    #[error(
        "{}: is both a file to write ({option}) and the folder of {} ({inner_option})",
        path.display(), inner.display()
    )]
    FileIsFolderOfAnother {
        path: PathBuf,
        option: String,
        inner: PathBuf,
        inner_option: String,
    },
    #[error("{option}: an empty path (give the file or directory to write)")]
    EmptyPath { option: String },
    #[error("{}: is a directory, not a file to write ({option})", path.display())]
    FileIsDirectory { path: PathBuf, option: String },
    #[error("{}: is a file, not a directory ({option} names the directory to write into)", path.display())]
    FolderIsFile { path: PathBuf, option: String },
    #[error("{}: {} is not a directory, nothing can be written below it ({option})", path.display(), parent.display())]
    BelowNonDirectory {
        path: PathBuf,
        parent: PathBuf,
        option: String,
    },
    #[error(
        "{}: is {kind}, not a regular file: a named output is only written into a regular file \
         ({option}; refused even with --force)",
        path.display()
    )]
    NotRegularFile {
        path: PathBuf,
        kind: FileKind,
        option: String,
    },
    #[error(
        "{}: is a symbolic link to {}, which does not exist ({option}); name the file itself",
        path.display(), target.display()
    )]
    LinkToNothing {
        path: PathBuf,
        target: PathBuf,
        option: String,
    },
    #[error(
        "{}: is {kind}, not the {} learn made there ({option}): refusing to write through it, \
         even with --force; move it away",
        path.display(),
        match expected { Leaf::File => "file", Leaf::Folder => "folder" }
    )]
    NotMadeByLearn {
        path: PathBuf,
        kind: FileKind,
        expected: Leaf,
        option: String,
    },
    #[error(
        "{}: a commit interrupted here was shared with {}, whose journal is gone: learn cannot \
         tell whether to finish or undo it; compare the folders, then move this journal away",
        journal.display(), lead.display()
    )]
    UnresolvableCommit { journal: PathBuf, lead: PathBuf },
    #[error("{}: already exists (pass --force to overwrite)", path.display())]
    Exists { path: PathBuf },
    #[error("{}: already exists, written by an earlier `learn {producer}` (pass --force to replace it)", path.display())]
    OwnExists { path: PathBuf, producer: String },
    #[error(
        "{}: already exists and was not written by learn (it is not in {}): a command never \
         replaces a file it did not write; move it away or choose another {option}",
        path.display(), manifest.display()
    )]
    Foreign {
        path: PathBuf,
        manifest: PathBuf,
        option: String,
    },
    #[error(
        "{}: another learn run is writing into this directory ({option}); wait for it to end, \
         or choose another directory",
        dir.display()
    )]
    Locked { dir: PathBuf, option: String },
    #[error("{}: cannot be written ({option}): {source}", path.display())]
    NotWritable {
        path: PathBuf,
        option: String,
        source: std::io::Error,
    },
    #[error("{}: {source}", path.display())]
    Io {
        path: PathBuf,
        source: std::io::Error,
    },
    #[error("{}: {message}", path.display())]
    Manifest { path: PathBuf, message: String },
}

/// Results of this crate.
pub type Result<T, E = OutputError> = std::result::Result<T, E>;

/// Maps an I/O error on `path` to [`OutputError::Io`].
pub(crate) fn io(path: &std::path::Path) -> impl FnOnce(std::io::Error) -> OutputError + '_ {
    move |source| OutputError::Io {
        path: path.to_path_buf(),
        source,
    }
}
