//! The checks of a variants file, each refusal naming the file and the field.

use std::path::Path;

use crate::variants::testing::{LEARNED, RIDGE, config, write};
use crate::variants::{MAX_VARIANTS, VariantsConfig};

#[test]
fn a_learn_ensemble_is_checked_when_the_file_is_read() {
    let ensemble = |members: &str| {
        format!(
            r#"{{"name": "a", "description": "", "kind": "learn_ensemble", "members": {members}}}"#
        )
    };
    let message = read_error("ensemble-one", &ensemble("1"), "");
    assert!(
        message.ends_with(
            "variants[0] (a).members: 1 members; an ensemble has 2 to 8 (evaluation::MAX_ENSEMBLE_MEMBERS), each a full meta-training"
        ),
        "{message}"
    );
    let message = read_error("ensemble-many", &ensemble("100"), "");
    assert!(message.contains("100 members"), "{message}");
    let overflow = config(&ensemble("3"), "")
        .replace(r#""seeds": [1]"#, r#""seeds": [1, 18446744073709551000]"#);
    let path = write("ensemble-overflow", &overflow);
    let message = VariantsConfig::read(&path).unwrap_err().to_string();
    assert!(
        message.contains("seeds: seed 18446744073709551000 leaves no room"),
        "{message}"
    );
    // Shown in make reproduce's columns, directly or through an average: refused.
    let a = format!(r#"{{"name": "r", "description": "", {RIDGE}}}"#);
    let average = r#"{"name": "m", "description": "", "kind": "average", "members": ["r", "a"]}"#;
    for (name, extra) in [
        ("ensemble-reproduce", r#""reproduce": ["a"],"#),
        ("ensemble-reproduce-member", r#""reproduce": ["m"],"#),
    ] {
        let variants = format!("{a}, {}, {average}", ensemble("3"));
        let message = read_error(name, &variants, extra);
        assert!(
            message
                .contains("reproduce: 'a' (or a member of a listed variant) is a learn_ensemble"),
            "{name}: {message}"
        );
    }
}

#[test]
fn the_variants_file_is_checked() {
    let a = format!(r#"{{"name": "a", "description": "", {RIDGE}}}"#);
    let b = format!(r#"{{"name": "b", "description": "", {LEARNED}}}"#);
    let select = r#"{"name": "s", "description": "", "kind": "select", "candidates": ["a"]}"#;
    let good = write(
        "good",
        &config(&format!("{a}, {b}, {select}"), r#""reproduce": ["s"],"#),
    );
    let read = VariantsConfig::read(&good).unwrap();
    assert_eq!(read.reproduce_variants().len(), 2);

    let cases = [
        ("twice", config(&format!("{a}, {a}"), ""), "declared twice"),
        (
            "forward",
            config(&format!("{select}, {a}"), ""),
            "declared before it",
        ),
        (
            "headline",
            config(&b.replace("\"b\"", "\"c\""), ""),
            "'a' is not",
        ),
        (
            "member",
            config(
                &format!(
                    r#"{a}, {{"name": "m", "description": "", "kind": "average", "members": ["a", "z"]}}"#
                ),
                "",
            ),
            "member 'z' must be a variant declared before it",
        ),
        (
            "no-score",
            config(
                &format!(
                    r#"{a}, {{"name": "l", "description": "", "kind": "learn"}}, {{"name": "s", "description": "", "kind": "select", "candidates": ["a", "l"]}}"#
                ),
                "",
            ),
            "no support cross-validation score",
        ),
    ];
    let learn_average = write(
        "learn-average",
        &config(
            &format!(
                r#"{a}, {{"name": "l", "description": "", "kind": "learn"}}, {{"name": "m", "description": "", "kind": "average", "members": ["l", "a"]}}"#
            ),
            "",
        ),
    );
    let read = VariantsConfig::read(&learn_average).unwrap();
    assert_eq!(read.equations_variant("m"), Some("a"));
    assert_eq!(read.equations_variant("l"), None);
    // The paper's LeARN needs the meta-trained networks as much as a learned basis does.
    let needs: Vec<bool> = read
        .variants
        .iter()
        .map(|v| v.kind.needs_meta_training())
        .collect();
    assert_eq!(needs, [false, true, false]);
    let cases = cases.into_iter().chain([
        (
            "seeds",
            config(&a, "").replace("[1]", "[1, 1]"),
            "seed 1 is listed twice",
        ),
        (
            "unnamed",
            config(&a.replace("\"a\"", "\" \""), ""),
            "variant 1 has no name",
        ),
    ]);
    for (name, text, expected) in cases {
        let message = VariantsConfig::read(&write(name, &text))
            .err()
            .unwrap_or_else(|| panic!("{name} was accepted"))
            .to_string();
        assert!(message.contains(expected), "{name}: {message}");
    }
}

/// `VariantsConfig::read`'s error for the variants `variants` (headline `a`), one line.
fn read_error(name: &str, variants: &str, extra: &str) -> String {
    let path = write(name, &config(variants, extra));
    let start = std::time::Instant::now();
    let message = VariantsConfig::read(&path)
        .err()
        .unwrap_or_else(|| panic!("{name} was accepted"))
        .to_string();
    assert!(
        start.elapsed().as_secs() < 5,
        "{name}: {:?}",
        start.elapsed()
    );
    assert!(!message.contains('\n'), "{name}: {message}");
    assert!(
        message.starts_with(&format!("{}: ", path.display())),
        "{name}: {message}"
    );
    message
}

#[test]
fn every_variant_spec_is_checked_when_the_file_is_read() {
    let library = |library: &str, regression: &str| {
        format!(
            r#"{{"name": "a", "description": "", "kind": "library", "library": {library}, "regression": {regression}}}"#
        )
    };
    let linear = r#"{"linear": true}"#;
    let ridge = r#"{"penalty": {"kind": "ridge", "lambdas": [0.0]}}"#;
    let many = |count: usize, value: &str| vec![value; count].join(", ");
    let cases = [
        (
            "bag-block0",
            library(
                linear,
                r#"{"penalty": {"kind": "ridge", "lambdas": [0.0]}, "bagging": {"members": 3, "block": 0}}"#,
            ),
            "variants[0] (a).regression.bagging.block: 0 must be from 1",
        ),
        (
            "bag-huge",
            library(
                linear,
                r#"{"penalty": {"kind": "ridge", "lambdas": [0.0]}, "bagging": {"members": 1000000000, "block": 125}}"#,
            ),
            "variants[0] (a).regression.bagging.members: 1000000000 must be from 2 to 1000",
        ),
        (
            "fractions-bad",
            library(
                linear,
                r#"{"penalty": {"kind": "lasso", "fractions": [0.1, 2]}}"#,
            ),
            "variants[0] (a).regression.penalty.fractions: 2 must be in (0, 1]",
        ),
        (
            "lambdas-neg",
            library(
                linear,
                r#"{"penalty": {"kind": "ridge", "lambdas": [0.1, -1]}}"#,
            ),
            "variants[0] (a).regression.penalty.lambdas: -1 must be ≥ 0",
        ),
        (
            "lambdas-many",
            library(
                linear,
                &format!(
                    r#"{{"penalty": {{"kind": "ridge", "lambdas": [{}]}}}}"#,
                    many(1_000_000, "0.5")
                ),
            ),
            "variants[0] (a).regression.penalty.lambdas: 1000000 candidates, more than the limit of 100",
        ),
        (
            "thresholds-neg",
            library(
                linear,
                r#"{"penalty": {"kind": "stlsq", "thresholds": [-0.1], "alpha": 0.05}}"#,
            ),
            "variants[0] (a).regression.penalty.thresholds: -0.1 must be ≥ 0",
        ),
        (
            "lib-empty",
            library("{}", ridge),
            "variants[0] (a).library: the library has no feature",
        ),
        (
            "lags-bad",
            library(r#"{"control_lags": [0.5, 1.5]}"#, ridge),
            "variants[0] (a).library.control_lags: pole 1.5 must lie in [0, 1)",
        ),
        (
            "lags-twice",
            library(r#"{"control_lags": [0.5, 0.8, 0.8]}"#, ridge),
            "variants[0] (a).library.control_lags: pole 0.8 is listed twice",
        ),
        (
            "lags-many",
            library(
                &format!(r#"{{"control_lags": [{}]}}"#, many(100_000, "0.5")),
                ridge,
            ),
            "variants[0] (a).library.control_lags: 100000 lags, more than the limit of 100",
        ),
        (
            "fourier-huge",
            library(r#"{"fourier": 1000000000}"#, ridge),
            "variants[0] (a).library.fourier: 1000000000 frequencies",
        ),
        (
            "folds",
            library(
                linear,
                r#"{"penalty": {"kind": "ridge", "lambdas": [0.0]}, "folds": {"folds": 1}}"#,
            ),
            "variants[0] (a).regression.folds.folds: 1 must be from 2",
        ),
        (
            "learned-basis",
            format!(
                r#"{{"name": "a", "description": "", "kind": "learned_basis", "features": "basis", "library": {{"fourier": 1000000}}, "regression": {ridge}}}"#
            ),
            "variants[0] (a).library.fourier",
        ),
    ];
    for (name, variants, expected) in cases {
        let message = read_error(name, &variants, "");
        assert!(message.contains(expected), "{name}: {message}");
    }
}

#[test]
fn counts_and_repeated_names_are_checked_when_the_file_is_read() {
    let a = format!(r#"{{"name": "a", "description": "", {RIDGE}}}"#);
    let seeds = config(&a, "").replace(
        r#""seeds": [1]"#,
        &format!(
            r#""seeds": [{}]"#,
            (0..100_000)
                .map(|s| s.to_string())
                .collect::<Vec<_>>()
                .join(", ")
        ),
    );
    let message = VariantsConfig::read(&write("seeds-many", &seeds))
        .unwrap_err()
        .to_string();
    assert!(
        message.contains("seeds: 100000 seeds, more than the limit of 100"),
        "{message}"
    );
    let select = r#"{"name": "s", "description": "", "kind": "select", "candidates": ["a", "a"]}"#;
    let message = read_error("candidates-twice", &format!("{a}, {select}"), "");
    assert!(
        message.contains("variants[1] (s).candidates: candidate 'a' is listed twice"),
        "{message}"
    );
    let message = read_error("reproduce-twice", &a, r#""reproduce": ["a", "a"],"#);
    assert!(
        message.contains("reproduce: 'a' is listed twice"),
        "{message}"
    );
    let many_variants = (0..=MAX_VARIANTS)
        .map(|k| a.replace(r#""a""#, &format!(r#""a{k}""#)))
        .collect::<Vec<_>>()
        .join(", ");
    let message = read_error("variants-many", &many_variants, "");
    assert!(
        message.contains("201 variants, more than the limit of 200"),
        "{message}"
    );
}

#[test]
fn variant_names_that_break_tables_or_files_are_refused() {
    let variant = |name: &str| {
        format!(
            r#"{{"name": {}, "description": "", {RIDGE}}}"#,
            serde_json::to_string(name).unwrap()
        )
    };
    for (index, name) in ["a|b\nc", "a b", "`a`", "a/b", "a\\b", "<a>"]
        .iter()
        .enumerate()
    {
        let message = read_error(&format!("name-{index}"), &variant(name), "");
        assert!(
            message.contains("variants[0].name: ") && message.contains("may hold only"),
            "{name}: {message}"
        );
    }
    for name in ["lag-ridge-cv", "a_b.c+d", "ridge2"] {
        let text = config(&variant(name), "")
            .replace(r#""headline": "a""#, &format!(r#""headline": "{name}""#));
        VariantsConfig::read(&write("name-good", &text)).unwrap();
    }
}

#[test]
fn folds_and_blocks_are_checked_against_the_segment_before_any_fit() {
    let bagged = r#"{"name": "b", "description": "", "kind": "library", "library": {"linear": true},
           "regression": {"penalty": {"kind": "ridge", "lambdas": [0.0]}, "bagging": {"members": 3, "block": 500}}}"#;
    let a = format!(r#"{{"name": "a", "description": "", {RIDGE}}}"#);
    let path = write(
        "check-rows",
        &config(&format!("{a}, {bagged}"), r#""reproduce": ["a"],"#),
    );
    let read = VariantsConfig::read(&path).unwrap();
    read.check_rows(&path, 1255, "the segment", false).unwrap();
    let message = read
        .check_rows(&path, 400, "the full support segment of f.csv", false)
        .unwrap_err()
        .to_string();
    assert_eq!(
        message,
        format!(
            "{}: variants[1] (b).regression.bagging.block: blocks of 500 samples are longer \
             than the segment's 400 samples (the full support segment of f.csv)",
            path.display()
        )
    );
    // `make reproduce` runs `a` only.
    read.check_rows(&path, 400, "the segment", true).unwrap();
    let message = read
        .check_rows(&path, 20, "the segment", true)
        .unwrap_err()
        .to_string();
    assert!(
        message.contains("variants[0] (a).regression.folds: 20 samples are too few"),
        "{message}"
    );
}

#[test]
fn the_committed_variants_are_within_every_limit() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../experiments/variants.json");
    let read = VariantsConfig::read(&path).unwrap();
    assert_eq!(read.variants.len(), 15);
}
