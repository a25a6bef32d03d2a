//! Comparing and checking paths of files a command will read or write, existing or not.

use std::fs::Metadata;
use std::path::{Component, Path, PathBuf};

/// What a path is on disk, the path itself (a symbolic link is not followed).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FileKind {
    Regular,
    Directory,
    SymbolicLink,
    Fifo,
    CharacterDevice,
    BlockDevice,
    Socket,
}

impl FileKind {
    /// The kind of the file `metadata` describes.
    pub fn of(metadata: &Metadata) -> Self {
        use std::os::unix::fs::FileTypeExt;
        let kind = metadata.file_type();
        if kind.is_symlink() {
            Self::SymbolicLink
        } else if kind.is_dir() {
            Self::Directory
        } else if kind.is_fifo() {
            Self::Fifo
        } else if kind.is_char_device() {
            Self::CharacterDevice
        } else if kind.is_block_device() {
            Self::BlockDevice
        } else if kind.is_socket() {
            Self::Socket
        } else {
            Self::Regular
        }
    }

    /// The kind of `path` itself; `None` when nothing is there.
    pub fn of_path(path: &Path) -> Option<Self> {
        std::fs::symlink_metadata(path).ok().map(|m| Self::of(&m))
    }
}

impl std::fmt::Display for FileKind {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            Self::Regular => "a regular file",
            Self::Directory => "a directory",
            Self::SymbolicLink => "a symbolic link",
            Self::Fifo => "a FIFO (named pipe)",
            Self::CharacterDevice => "a character device",
            Self::BlockDevice => "a block device",
            Self::Socket => "a socket",
        })
    }
}

/// What the last component of a path below an output folder is meant to be.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Leaf {
    File,
    Folder,
}

/// The first existing component of `relative` below `dir` that is not what `learn` makes there,
/// with its kind: every folder on the way must be a directory, not a link to one (which would
/// send the writes into a folder `learn` does not own), and the last component a regular file
/// ([`Leaf::File`]) or a directory ([`Leaf::Folder`]). `None` when all are, or do not exist yet.
pub fn first_foreign_component(
    dir: &Path,
    relative: &Path,
    leaf: Leaf,
) -> Option<(PathBuf, FileKind)> {
    let components: Vec<Component> = relative.components().collect();
    let mut path = dir.to_path_buf();
    for (index, component) in components.iter().enumerate() {
        path.push(component);
        let kind = FileKind::of_path(&path)?;
        let last = index + 1 == components.len();
        let expected = if last && leaf == Leaf::File {
            FileKind::Regular
        } else {
            FileKind::Directory
        };
        if kind != expected {
            return Some((path, kind));
        }
    }
    None
}

/// Whether `a` and `b` name the same file, existing or not, whatever the spelling: the same
/// existing file (also through links), or the same place once the longest existing ancestor of
/// each is resolved by the operating system (links, `.` and `..` in it) and the rest of the path
/// applied to it (`.` dropped, `..` taken as the parent).
pub fn same_file(a: &Path, b: &Path) -> bool {
    #[cfg(unix)]
    {
        use std::os::unix::fs::MetadataExt;
        if let (Ok(a), Ok(b)) = (std::fs::metadata(a), std::fs::metadata(b)) {
            return a.dev() == b.dev() && a.ino() == b.ino();
        }
    }
    match (resolved(a), resolved(b)) {
        (Some(a), Some(b)) => a == b,
        _ => false,
    }
}

/// The nearest existing ancestor of `path` (not `path` itself) when it is not a directory: nothing
/// can be created below it. `None` when that ancestor is a directory or none exists.
pub fn non_directory_ancestor(path: &Path) -> Option<&Path> {
    path.ancestors()
        .skip(1)
        .filter(|parent| !parent.as_os_str().is_empty())
        .find(|parent| parent.exists())
        .filter(|parent| !parent.is_dir())
}

/// `path` made absolute, its longest ancestor as given that the operating system can resolve
/// canonicalised (links and `..` resolved in that order, as the OS does), then its remaining
/// components applied lexically (`.` dropped, `..` pops). `None` if the current directory is
/// unknown.
pub(crate) fn resolved(path: &Path) -> Option<PathBuf> {
    let absolute = std::env::current_dir().ok()?.join(path);
    let mut base = absolute.as_path();
    let mut rest = Vec::new();
    let mut resolved = loop {
        if let Ok(canonical) = base.canonicalize() {
            break canonical;
        }
        let mut components = base.components();
        rest.push(components.next_back()?);
        base = components.as_path();
    };
    for component in rest.into_iter().rev() {
        match component {
            Component::CurDir => {}
            Component::ParentDir => {
                resolved.pop();
            }
            other => resolved.push(other),
        }
    }
    Some(resolved)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn same_file_sees_through_spellings_of_paths_that_do_not_exist_yet() {
        let tmp = tempfile::Builder::new()
            .prefix("data-same-file-")
            .tempdir()
            .unwrap();
        let dir = tmp.path();
        std::fs::create_dir_all(dir.join("ck")).unwrap();
        let plain = dir.join("ck/a.json");
        assert!(same_file(&plain, &dir.join("ck/./a.json")));
        assert!(same_file(&plain, &dir.join("ck/../ck/a.json")));
        assert!(same_file(
            &dir.join("new/x.json"),
            &dir.join("new/sub/../x.json")
        ));
        assert!(same_file(
            &dir.join("new/x.json"),
            &dir.join("new/./sub/./../x.json")
        ));
        assert!(!same_file(&plain, &dir.join("ck/b.json")));
        std::fs::write(&plain, "{}").unwrap();
        assert!(same_file(&plain, &dir.join("./ck/a.json")));
        #[cfg(unix)]
        {
            std::os::unix::fs::symlink(dir.join("ck"), dir.join("link")).unwrap();
            assert!(same_file(&dir.join("link/c.json"), &dir.join("ck/c.json")));
            // `..` after a link is the parent of the link's target, not of the link.
            std::fs::create_dir_all(dir.join("other/sub")).unwrap();
            std::os::unix::fs::symlink(dir.join("other/sub"), dir.join("l")).unwrap();
            assert!(same_file(&dir.join("l/../x"), &dir.join("other/x")));
            assert!(!same_file(&dir.join("l/../x"), &dir.join("x")));
            assert!(same_file(&dir.join("l/../new/../x"), &dir.join("other/x")));
        }
    }

    #[test]
    fn links_and_special_files_below_an_output_folder_are_found() {
        let tmp = tempfile::Builder::new()
            .prefix("data-foreign-")
            .tempdir()
            .unwrap();
        let dir = tmp.path();
        let foreign = tempfile::tempdir().unwrap();
        std::fs::create_dir(dir.join("tables")).unwrap();
        std::fs::write(dir.join("tables/a.json"), "").unwrap();
        std::os::unix::fs::symlink(foreign.path(), dir.join("figures")).unwrap();
        std::os::unix::fs::symlink(dir.join("tables/a.json"), dir.join("tables/b.json")).unwrap();
        assert_eq!(
            first_foreign_component(dir, Path::new("tables/a.json"), Leaf::File),
            None
        );
        assert_eq!(
            first_foreign_component(dir, Path::new("tables/new/c.json"), Leaf::File),
            None
        );
        assert_eq!(
            first_foreign_component(dir, Path::new("figures/x.svg"), Leaf::File),
            Some((dir.join("figures"), FileKind::SymbolicLink))
        );
        assert_eq!(
            first_foreign_component(dir, Path::new("figures"), Leaf::Folder),
            Some((dir.join("figures"), FileKind::SymbolicLink))
        );
        assert_eq!(
            first_foreign_component(dir, Path::new("tables/b.json"), Leaf::File),
            Some((dir.join("tables/b.json"), FileKind::SymbolicLink))
        );
        assert_eq!(
            first_foreign_component(dir, Path::new("tables/a.json/x"), Leaf::File),
            Some((dir.join("tables/a.json"), FileKind::Regular))
        );
    }

    #[test]
    fn a_file_among_the_ancestors_is_found() {
        let tmp = tempfile::Builder::new()
            .prefix("data-ancestor-")
            .tempdir()
            .unwrap();
        let dir = tmp.path();
        assert_eq!(non_directory_ancestor(&dir.join("a/b.csv")), None);
        std::fs::write(dir.join("a"), "").unwrap();
        assert_eq!(
            non_directory_ancestor(&dir.join("a/sub/b.csv")),
            Some(dir.join("a").as_path())
        );
        assert_eq!(non_directory_ancestor(Path::new("b.csv")), None);
    }
}
