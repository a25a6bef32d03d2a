//! `learn check-paper` never passes on an ambiguous or empty check: a table in two files, a
//! published file with nothing to check, a tolerance rule that matches nothing because of a typing
//! error, or an implausible published value is a one-line error naming the files and the field.

mod common;

use std::path::{Path, PathBuf};

use common::{learn_in, scratch};

fn workspace() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// A copy of the committed results tables in `dir/t`.
fn copy_results(dir: &Path) -> PathBuf {
    let tables = dir.join("t");
    std::fs::create_dir_all(&tables).unwrap();
    for entry in std::fs::read_dir(workspace().join("results/tables")).unwrap() {
        let path = entry.unwrap().path();
        if path.extension().is_some_and(|e| e == "json") {
            std::fs::copy(&path, tables.join(path.file_name().unwrap())).unwrap();
        }
    }
    tables
}

fn check_paper(dir: &Path, published: &Path, tolerances: &Path) -> common::Run {
    learn_in(
        dir,
        &[
            "check-paper",
            "--results",
            "t",
            "--published",
            published.to_str().unwrap(),
            "--tolerances",
            tolerances.to_str().unwrap(),
        ],
    )
}

fn edit_json(from: &Path, to: &Path, edit: impl FnOnce(&mut serde_json::Value)) {
    let mut value: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(from).unwrap()).unwrap();
    edit(&mut value);
    std::fs::write(to, value.to_string()).unwrap();
}

#[test]
fn a_table_in_two_files_is_an_error_naming_both() {
    let dir = scratch("check-paper-two-files");
    let tables = copy_results(&dir);
    let paper = workspace().join("paper");
    let (published, tolerances) = (paper.join("published.json"), paper.join("tolerances.json"));
    check_paper(&dir, &published, &tolerances).success();
    edit_json(
        &tables.join("translational.json"),
        &tables.join("zzz.json"),
        |v| {
            for row in v["rows"].as_array_mut().unwrap() {
                row["learn"]["gen"] = 5.0.into();
            }
        },
    );
    check_paper(&dir, &published, &tolerances).one_line_error(&[
        "zzz.json: table: 'translational' is also the table of",
        "t/translational.json",
    ]);
}

#[test]
fn nothing_to_check_unknown_rule_names_and_implausible_values_are_errors() {
    let dir = scratch("check-paper-nothing");
    copy_results(&dir);
    let paper = workspace().join("paper");
    let (published, tolerances) = (paper.join("published.json"), paper.join("tolerances.json"));

    // Tables without conditions: zero cells checked.
    let empty = dir.join("empty.json");
    edit_json(&published, &empty, |v| {
        for table in v["tables"].as_object_mut().unwrap().values_mut() {
            *table = serde_json::json!({});
        }
    });
    check_paper(&dir, &empty, &tolerances).one_line_error(&[
        "empty.json: tables.",
        ": no condition: there is nothing to check",
    ]);

    // A rule whose table or condition is misspelt would apply to nothing.
    let misspelt = dir.join("tolerances.json");
    for (field, value, index) in [("table", "translatonal", 0), ("condition", "35Wind", 1)] {
        edit_json(&tolerances, &misspelt, |v| {
            v["rules"][index][field] = value.into();
        });
        let rule = format!("tolerances.json: rules[{index}].{field}: '{value}' is not a");
        check_paper(&dir, &published, &misspelt).one_line_error(&[&rule]);
    }

    // A published value that is no mean squared error.
    let bad = dir.join("bad.json");
    for value in [-0.1, 1e308] {
        edit_json(&published, &bad, |v| {
            v["tables"]["attitude"]["70wind"]["learn"]["gen"] = value.into();
        });
        check_paper(&dir, &bad, &tolerances).one_line_error(&[
            "bad.json: tables.attitude.70wind.learn.gen:",
            "is not a published mean squared error",
        ]);
    }
}
