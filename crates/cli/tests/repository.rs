//! The repository as a newcomer meets it: each of the README's two commands does its own set-up
//! (the Makefile's graph), and the README and `docs/` hold no broken relative link, no path into a
//! file or folder that does not exist, and no path of a developer's machine.

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};
use std::process::Command;

/// The repository root (two levels above this crate).
fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../..")
        .canonicalize()
        .expect("the repository root")
}

/// The commands `make` would run for `target`, every target out of date, without running any.
fn dry_run(target: &str) -> Vec<String> {
    let output = Command::new("make")
        .args(["--dry-run", "--always-make", "--no-print-directory", target])
        .current_dir(root())
        .env_remove("MAKEFLAGS")
        .output()
        .expect("make runs");
    assert!(output.status.success(), "make -n {target}: {output:?}");
    String::from_utf8_lossy(&output.stdout)
        .lines()
        .map(str::to_string)
        .collect()
}

/// The index of the first line of `lines` containing `needle`.
fn first(lines: &[String], needle: &str) -> Option<usize> {
    lines.iter().position(|line| line.contains(needle))
}

#[test]
fn every_target_that_reads_flights_or_runs_learn_sets_itself_up() {
    let needs_data = [
        "reproduce",
        "test",
        "check-paper",
        "ablations",
        "bench",
        "mismatch-demo",
    ];
    for target in needs_data.iter().chain(&["own-data-example"]) {
        let lines = dry_run(target);
        let build = first(&lines, "build --workspace")
            .unwrap_or_else(|| panic!("make {target} does not build first: {lines:#?}"));
        if let Some(run) = first(&lines, "target/debug/learn") {
            assert!(build < run, "make {target} runs learn before the build");
        }
        if needs_data.contains(target) {
            let data = first(&lines, "scripts/fetch-data.sh")
                .unwrap_or_else(|| panic!("make {target} does not fetch the data: {lines:#?}"));
            let uses = first(&lines, "target/debug/learn")
                .or_else(|| first(&lines, "test --workspace"))
                .or_else(|| first(&lines, "scripts/bench"))
                .unwrap_or_else(|| panic!("make {target} runs nothing: {lines:#?}"));
            assert!(
                data < uses,
                "make {target} uses the data before fetching it"
            );
        }
    }
}

/// Every Markdown file of the repository a reader is pointed to (generated results included,
/// build output, data and virtual environments not).
fn markdown_files() -> Vec<PathBuf> {
    let skip = [
        "target",
        "data",
        ".git",
        ".venv",
        ".venv-torch",
        ".venv-ulog",
        ".venv-python",
        ".scratch",
    ];
    let mut found = Vec::new();
    let mut folders = vec![root()];
    while let Some(folder) = folders.pop() {
        for entry in std::fs::read_dir(&folder)
            .expect("readable folder")
            .flatten()
        {
            let path = entry.path();
            let name = entry.file_name().to_string_lossy().to_string();
            if path.is_dir() && !skip.contains(&name.as_str()) && !name.starts_with(".learn-") {
                folders.push(path);
            } else if name.ends_with(".md") {
                found.push(path);
            }
        }
    }
    found.sort();
    found
}

/// The lines of `text` outside fenced code blocks, with their line numbers (from 1).
fn prose_lines(text: &str) -> Vec<(usize, String)> {
    let mut fenced = false;
    let mut lines = Vec::new();
    for (index, line) in text.lines().enumerate() {
        if line.trim_start().starts_with("```") {
            fenced = !fenced;
        } else if !fenced {
            lines.push((index + 1, line.to_string()));
        }
    }
    lines
}

/// `line` split into prose and code spans: (is_code, text) pieces.
fn spans(line: &str) -> Vec<(bool, String)> {
    let mut pieces = Vec::new();
    for (index, piece) in line.split('`').enumerate() {
        pieces.push((index % 2 == 1, piece.to_string()));
    }
    pieces
}

/// The targets of the Markdown links and images of a prose piece: `[text](target)`.
fn link_targets(prose: &str) -> Vec<String> {
    let mut targets = Vec::new();
    let mut rest = prose;
    while let Some(start) = rest.find("](") {
        let after = &rest[start + 2..];
        let Some(end) = after.find(')') else { break };
        let target = after[..end].trim();
        let target = target.split_whitespace().next().unwrap_or_default();
        targets.push(target.trim_matches(['<', '>']).to_string());
        rest = &after[end..];
    }
    targets
}

/// GitHub's anchor of a heading: lower case, spaces as '-', punctuation other than '-' and '_'
/// dropped.
fn anchor(heading: &str) -> String {
    heading
        .trim()
        .chars()
        .filter_map(|c| match c {
            ' ' => Some('-'),
            c if c.is_alphanumeric() || c == '-' || c == '_' => Some(c.to_ascii_lowercase()),
            _ => None,
        })
        .flat_map(char::to_lowercase)
        .collect()
}

/// The anchors of the headings of a Markdown file.
fn anchors(text: &str) -> BTreeSet<String> {
    prose_lines(text)
        .iter()
        .filter_map(|(_, line)| line.strip_prefix('#'))
        .map(|heading| anchor(heading.trim_start_matches('#').replace('`', "").as_str()))
        .collect()
}

/// What is wrong with the link `target` of `file` (None: it resolves).
fn broken_link(file: &Path, target: &str) -> Option<String> {
    if target.is_empty() || target.contains("://") || target.starts_with("mailto:") {
        return None;
    }
    let (path, fragment) = target.split_once('#').unwrap_or((target, ""));
    let resolved = if path.is_empty() {
        file.to_path_buf()
    } else if path.starts_with('/') {
        return Some("an absolute path".to_string());
    } else {
        file.parent().expect("a folder").join(path)
    };
    if !resolved.exists() {
        return Some("no such file or folder".to_string());
    }
    if !fragment.is_empty() && resolved.extension().is_some_and(|e| e == "md") {
        let text = std::fs::read_to_string(&resolved).expect("readable");
        if !anchors(&text).contains(fragment) {
            return Some(format!("no heading with anchor #{fragment}"));
        }
    }
    None
}

/// Prefixes of paths on a developer's machine that must not appear in what a reader reads.
const MACHINE_PATHS: [&str; 6] = [
    "/work/",
    "/home/",
    "/root/",
    "/Users/",
    "/tmp/bash_",
    "C:\\",
];

/// Top-level folders of the repository: a code span starting with one is a path that must exist
/// (globs, braces and placeholders aside).
const REPOSITORY_FOLDERS: [&str; 6] = [
    "crates/",
    "docs/",
    "scripts/",
    "experiments/",
    "paper/",
    ".ci/",
];

/// A code span that names a path in the repository that does not exist.
fn missing_repository_path(code: &str) -> Option<String> {
    let path = code.trim().trim_end_matches([',', '.', ':', ';']);
    let names_a_path = REPOSITORY_FOLDERS
        .iter()
        .any(|folder| path.starts_with(folder))
        && !path.contains(|c: char| c.is_whitespace() || "*{}<>[]$|".contains(c))
        && !path.contains("::");
    (names_a_path && !root().join(path).exists()).then(|| path.to_string())
}

#[test]
fn documentation_links_and_paths_resolve() {
    let mut problems = Vec::new();
    for file in markdown_files() {
        let text = std::fs::read_to_string(&file).expect("readable Markdown");
        let shown = file
            .strip_prefix(root())
            .unwrap_or(&file)
            .display()
            .to_string();
        for machine_path in MACHINE_PATHS {
            for (index, line) in text.lines().enumerate() {
                if line.contains(machine_path) {
                    problems.push(format!(
                        "{shown}:{}: machine path {machine_path}",
                        index + 1
                    ));
                }
            }
        }
        for (number, line) in prose_lines(&text) {
            for (is_code, piece) in spans(&line) {
                if is_code {
                    if let Some(path) = missing_repository_path(&piece) {
                        problems.push(format!("{shown}:{number}: `{path}` does not exist"));
                    }
                    continue;
                }
                for target in link_targets(&piece) {
                    if let Some(why) = broken_link(&file, &target) {
                        problems.push(format!("{shown}:{number}: link {target}: {why}"));
                    }
                }
            }
        }
    }
    assert!(problems.is_empty(), "{}", problems.join("\n"));
}

#[test]
fn the_link_check_catches_what_it_is_for() {
    let docs = root().join("docs/usage.md");
    assert!(broken_link(&docs, "docs/sindy-scale.md").is_some());
    assert!(broken_link(&docs, "sindy-scale.md").is_none());
    assert!(broken_link(&docs, "mismatch.md#no-such-heading").is_some());
    assert!(broken_link(&docs, "https://example.org/x").is_none());
    assert!(missing_repository_path("crates/evaluation/examples/select_settings.rs").is_some());
    assert!(missing_repository_path("crates/evaluation/examples/select_settings/").is_none());
    assert_eq!(
        anchor("5. The real flights: one vehicle, all flights"),
        "5-the-real-flights-one-vehicle-all-flights"
    );
    assert_eq!(
        link_targets("see [a](x.md) and ![b](y.svg \"t\")"),
        vec!["x.md", "y.svg"]
    );
}

/// The README's table of effects (its only rows starting with a code span) lists every effect of the registry (`physics::effects`), in its
/// order, by id: a new effect is documented where users look for it.
#[test]
fn the_readme_documents_every_effect_of_the_registry() {
    let readme = std::fs::read_to_string(root().join("README.md")).expect("README.md");
    let documented: Vec<&str> = readme
        .lines()
        .filter_map(|line| line.strip_prefix("| `"))
        .filter_map(|rest| rest.split_once('`').map(|(id, _)| id))
        .collect();
    let registry: Vec<&str> = physics::EffectId::ALL.map(physics::EffectId::name).to_vec();
    assert_eq!(documented, registry, "README.md's table of effects");
}
