//! The README and the help texts agree: every command line of the README's shell blocks parses as
//! written, every subcommand `learn --help` lists is named in the README, and the summary that
//! `learn --help` prints is the README's.

use clap::{CommandFactory, Parser};

use crate::commands::Cli;

/// The README, from the repository root.
fn readme() -> String {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../README.md");
    std::fs::read_to_string(path).expect("the README")
}

/// The `learn …` command lines of the README's shell blocks, each split into words as a shell
/// would (quotes removed, a trailing `# comment` dropped, `[`/`]` of optional parts removed).
fn readme_command_lines(readme: &str) -> Vec<Vec<String>> {
    let mut in_shell = false;
    let mut lines = Vec::new();
    for line in readme.lines() {
        if line.starts_with("```") {
            in_shell = line.trim() == "```sh";
            continue;
        }
        let line = line.trim();
        if in_shell && line.starts_with("learn ") {
            lines.push(shell_words(line));
        }
    }
    lines
}

/// Words of a command line: whitespace-separated, single or double quotes grouping, `#` at the
/// start of a word ending the line.
fn shell_words(line: &str) -> Vec<String> {
    let mut words = Vec::new();
    let mut word = String::new();
    let mut quote = None;
    let mut started = false;
    for c in line.chars() {
        match (quote, c) {
            (Some(q), c) if c == q => quote = None,
            (Some(_), c) => word.push(c),
            (None, '\'' | '"') => {
                quote = Some(c);
                started = true;
            }
            (None, '#') if !started => break,
            (None, c) if c.is_whitespace() => {
                if started {
                    words.push(std::mem::take(&mut word));
                }
                started = false;
            }
            (None, '[' | ']') => {}
            (None, c) => {
                word.push(c);
                started = true;
            }
        }
    }
    if started {
        words.push(word);
    }
    words
}

#[test]
fn every_command_line_of_the_readme_parses() {
    let lines = readme_command_lines(&readme());
    assert!(lines.len() >= 8, "the README's commands: {lines:?}");
    for words in lines {
        if let Err(error) = Cli::try_parse_from(&words).and_then(Cli::validated) {
            panic!("README: `{}` does not parse: {error}", words.join(" "));
        }
    }
}

#[test]
fn every_subcommand_is_in_the_readme_and_has_a_summary() {
    let readme = readme();
    let command = Cli::command();
    for subcommand in command.get_subcommands() {
        let name = subcommand.get_name();
        if name == "help" {
            continue;
        }
        let about = subcommand
            .get_about()
            .map(|a| a.to_string())
            .unwrap_or_default();
        assert!(
            about.len() > 20,
            "learn {name} --help says too little: {about:?}"
        );
        assert!(
            readme.contains(&format!("learn {name}")),
            "`learn {name}` is not in the README"
        );
    }
    let flatten = |text: &str| {
        text.split_whitespace()
            .collect::<Vec<_>>()
            .join(" ")
            .to_lowercase()
    };
    let summary = flatten(&command.get_about().expect("a summary").to_string());
    assert!(
        flatten(&readme).contains(&summary),
        "`learn --help` summarises the tool as the README does not: {summary}"
    );
}

#[test]
fn shell_words_are_split_as_a_shell_would() {
    assert_eq!(
        shell_words("learn meta-train --tasks 'runs/*.csv' --out m.json   # a task per CSV"),
        [
            "learn",
            "meta-train",
            "--tasks",
            "runs/*.csv",
            "--out",
            "m.json"
        ]
    );
    assert_eq!(
        shell_words("learn sindy --csv d.csv [--out model.json]"),
        ["learn", "sindy", "--csv", "d.csv", "--out", "model.json"]
    );
}
