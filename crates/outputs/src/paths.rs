//! Comparing and checking paths of files a command will read or write, existing or not.

use std::path::{Component, Path, PathBuf};

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
fn resolved(path: &Path) -> Option<PathBuf> {
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
