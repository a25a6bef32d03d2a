//! Bad input to sharded runs and to `learn merge`: a one-line error naming the option, file, field
//! or items, a non-zero exit, no panic, and nothing written. Shards here are the seed spread of
//! the translational cells on a small generated experiment (`common::sweep`): a fraction of a
//! second each.

mod common;

use std::path::{Path, PathBuf};

use common::sweep::{SmallExperiment, learn_at_once, small_experiment};
use common::{learn_in, scratch};

/// The spread command of `experiment` (translational cells), with `extra` options.
fn spread(experiment: &SmallExperiment, data: &Path, extra: &[&str]) -> Vec<String> {
    let mut args: Vec<String> = [
        "--quiet",
        "--data",
        SmallExperiment::arg(data),
        "meta-train",
        "--config",
        SmallExperiment::arg(&experiment.learn),
        "--conditions",
        SmallExperiment::arg(&experiment.conditions),
        "--protocol",
        "leave-condition-out",
        "--formulation",
        "translational",
        "--seed-spread",
    ]
    .iter()
    .map(|a| a.to_string())
    .collect();
    args.extend(extra.iter().map(|a| a.to_string()));
    args
}

/// Shards `which` of `count` of the spread on `data`, at once, into `<tag>-K-of-N`; their folders.
fn spread_shards(
    experiment: &SmallExperiment,
    data: &Path,
    count: usize,
    which: &[usize],
    tag: &str,
) -> Vec<PathBuf> {
    let dirs: Vec<PathBuf> = which
        .iter()
        .map(|k| experiment.dir.join(format!("{tag}-{k}-of-{count}")))
        .collect();
    let runs: Vec<Vec<String>> = which
        .iter()
        .zip(&dirs)
        .map(|(k, dir)| {
            let shard = format!("{k}/{count}");
            spread(
                experiment,
                data,
                &["--shard", &shard, "--out", SmallExperiment::arg(dir)],
            )
        })
        .collect();
    for run in learn_at_once(&experiment.dir, &runs) {
        run.success();
    }
    dirs
}

/// `learn merge --out merged.json SHARDS…` in the experiment's folder.
fn merge(experiment: &SmallExperiment, shards: &[&Path], extra: &[&str]) -> common::Run {
    let mut args = vec!["merge", "--out", "merged.json"];
    args.extend(extra);
    args.extend(shards.iter().map(|s| SmallExperiment::arg(s)));
    learn_in(&experiment.dir, &args)
}

/// `merge` must fail in one line naming every one of `needles`, writing nothing.
fn refused(experiment: &SmallExperiment, shards: &[&Path], needles: &[&str]) -> String {
    let run = merge(experiment, shards, &[]);
    let message = run.one_line_error(needles).to_string();
    assert!(!experiment.dir.join("merged.json").exists(), "{message}");
    message
}

#[test]
fn a_malformed_shard_is_a_usage_error_naming_it() {
    let dir = scratch("shard-malformed");
    let experiment = small_experiment(&dir);
    let cases = [
        ("3/3", "K = 3 is not below N = 3"),
        ("0/0", "N = 0"),
        ("1", "'1' is not K/N"),
        ("-1/2", "K = '-1'"),
        ("1/2/3", "N = '2/3'"),
    ];
    let variants = SmallExperiment::arg(&experiment.variants);
    let run_config = SmallExperiment::arg(&experiment.run);
    for (shard, message) in cases {
        for command in [
            vec![
                "reproduce",
                "--config",
                run_config,
                "--shard",
                shard,
                "--out",
                "s",
            ],
            vec![
                "ablations",
                "--config",
                variants,
                "--shard",
                shard,
                "--out",
                "s",
            ],
            vec![
                "meta-train",
                "--seed-spread",
                "--shard",
                shard,
                "--out",
                "s",
            ],
        ] {
            let run = learn_in(&dir, &command);
            run.one_line_usage_error(&["--shard <K/N>", &format!("'{shard}'"), message]);
        }
    }
    // A shard needs its folder, and writes nothing else.
    learn_in(&dir, &["reproduce", "--shard", "0/2"])
        .one_line_usage_error(&["required arguments were not provided: --out"]);
    learn_in(
        &dir,
        &[
            "reproduce",
            "--shard",
            "0/2",
            "--out",
            "s",
            "--latex-dir",
            "t",
        ],
    )
    .one_line_usage_error(&["'--shard <K/N>' cannot be used with '--latex-dir"]);
    learn_in(&dir, &["meta-train", "--shard", "0/2", "--out", "s"])
        .one_line_usage_error(&["required arguments were not provided: --seed-spread"]);
    assert!(!dir.join("s").exists() && !dir.join("results").exists());
}

#[test]
fn merge_names_the_missing_items_and_the_shards_to_run() {
    let dir = scratch("shard-missing");
    let experiment = small_experiment(&dir);
    let shards = spread_shards(&experiment, &experiment.data, 3, &[0, 2], "s");
    let message = refused(
        &experiment,
        &[&shards[0], &shards[1]],
        &[
            "the shards: 2 of 6 items are in no shard given: 1 (translational storm seed 1)",
            "(shards not given: 1/3)",
        ],
    );
    assert!(
        message.contains("; 4 (translational gust seed 3) ("),
        "{message}"
    );
}

#[test]
fn merge_names_the_items_given_twice() {
    let dir = scratch("shard-twice");
    let experiment = small_experiment(&dir);
    let shards = spread_shards(&experiment, &experiment.data, 2, &[0, 1], "s");
    let copy = dir.join("copy-of-0");
    std::fs::create_dir(&copy).unwrap();
    std::fs::copy(shards[0].join("shard.json"), copy.join("shard.json")).unwrap();
    refused(
        &experiment,
        &[&shards[0], &shards[1], &copy],
        &[
            "items given twice",
            "0 (translational gust seed 1) is in",
            "s-0-of-2/shard.json and",
            "copy-of-0/shard.json",
        ],
    );
}

#[test]
fn merge_refuses_shards_of_another_configuration_split_or_data() {
    let dir = scratch("shard-mixed");
    let experiment = small_experiment(&dir);
    let ours = spread_shards(&experiment, &experiment.data, 2, &[0], "s");
    // Another LeARN configuration: one more meta-iteration.
    let text = std::fs::read_to_string(&experiment.learn).unwrap();
    let mut config: serde_json::Value = serde_json::from_str(&text).unwrap();
    config["meta_training"]["iterations"] = 4.into();
    std::fs::write(&experiment.learn, config.to_string()).unwrap();
    let theirs = spread_shards(&experiment, &experiment.data, 2, &[1], "other-config");
    refused(
        &experiment,
        &[&ours[0], &theirs[0]],
        &[
            "other-config-1-of-2/shard.json: configuration_sha256: from a different configuration than",
            "s-0-of-2/shard.json",
            "first differ at context.config.meta_training.iterations",
        ],
    );
    std::fs::write(&experiment.learn, text).unwrap();
    // Another split of the same work.
    let thirds = spread_shards(&experiment, &experiment.data, 3, &[1], "thirds");
    refused(
        &experiment,
        &[&ours[0], &thirds[0]],
        &[
            "thirds-1-of-3/shard.json: shard: 1/3 splits the work into 3 shards",
            "(0/2) into 2",
        ],
    );
    // Other data: one flight changed.
    let other = dir.join("other-data");
    copy_dir(&experiment.data, &other);
    let changed = other.join("experiment/custom_figure8_baseline_storm.csv");
    common::sweep::flight(2.5).write_csv(&changed).unwrap();
    let theirs = spread_shards(&experiment, &other, 2, &[1], "other-data");
    refused(
        &experiment,
        &[&ours[0], &theirs[0]],
        &[
            "other-data-1-of-2/shard.json: data_files: run on different data than",
            "experiment/custom_figure8_baseline_storm.csv has SHA-256",
        ],
    );
}

fn copy_dir(from: &Path, to: &Path) {
    std::fs::create_dir_all(to).unwrap();
    for entry in std::fs::read_dir(from).unwrap() {
        let path = entry.unwrap().path();
        let target = to.join(path.file_name().unwrap());
        if path.is_dir() {
            copy_dir(&path, &target);
        } else {
            std::fs::copy(&path, &target).unwrap();
        }
    }
}

#[test]
fn merge_refuses_what_is_not_a_shard_of_the_same_command() {
    let dir = scratch("shard-not");
    let experiment = small_experiment(&dir);
    let shards = spread_shards(&experiment, &experiment.data, 2, &[0, 1], "s");
    std::fs::create_dir(dir.join("empty")).unwrap();
    refused(
        &experiment,
        &[&dir.join("empty")],
        &["empty: shard: not a shard folder"],
    );
    refused(
        &experiment,
        &[&dir.join("absent")],
        &["absent: shard: no such folder"],
    );
    std::fs::create_dir(dir.join("results")).unwrap();
    std::fs::write(
        dir.join("results/shard.json"),
        r#"{"format": "learn-results/1"}"#,
    )
    .unwrap();
    refused(
        &experiment,
        &[&dir.join("results")],
        &["results/shard.json: format: not a shard result (format 'learn-results/1'"],
    );
    std::fs::write(
        dir.join("results/shard.json"),
        "{\"format\": \"learn-shard/2\", ",
    )
    .unwrap();
    refused(
        &experiment,
        &[&dir.join("results")],
        &["results/shard.json", "line 1"],
    );
    // A shard edited after it was written (its context no longer matches its hash).
    let path = shards[1].join("shard.json");
    let mut shard: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&path).unwrap()).unwrap();
    shard["context"]["seeds"] = serde_json::json!([1, 2, 4]);
    let edited = dir.join("edited");
    std::fs::create_dir(&edited).unwrap();
    std::fs::write(edited.join("shard.json"), shard.to_string()).unwrap();
    refused(
        &experiment,
        &[&shards[0], &edited],
        &[
            "edited/shard.json: configuration_sha256:",
            "the file was changed after it was written",
        ],
    );
    // A shard of another command.
    let run_config = SmallExperiment::arg(&experiment.run);
    let data = SmallExperiment::arg(&experiment.data);
    let root = SmallExperiment::arg(&dir);
    learn_in(
        &dir,
        &[
            "--data",
            data,
            "reproduce",
            "--root",
            root,
            "--config",
            run_config,
            "--shard",
            "1/2",
            "--out",
            "reproduce-1",
        ],
    )
    .success();
    refused(
        &experiment,
        &[&shards[0], &dir.join("reproduce-1")],
        &[
            "reproduce-1/shard.json: kind: a shard of learn reproduce",
            "of learn meta-train --seed-spread",
        ],
    );
    // Options of a reproduce merge, given for spread shards, would be ignored.
    let run = merge(
        &experiment,
        &[&shards[0], &shards[1]],
        &["--latex-dir", "tex"],
    );
    run.one_line_error(&[
        "--latex-dir applies to reproduce shards only",
        "learn meta-train --seed-spread",
    ]);
    assert!(!dir.join("tex").exists() && !dir.join("merged.json").exists());
}

#[test]
fn merged_and_shard_outputs_never_replace_a_file_without_force() {
    let dir = scratch("shard-force");
    let experiment = small_experiment(&dir);
    let shards = spread_shards(&experiment, &experiment.data, 2, &[0, 1], "s");
    let both = [shards[0].as_path(), shards[1].as_path()];
    merge(&experiment, &both, &[]).success();
    let before = std::fs::read(dir.join("merged.json")).unwrap();
    merge(&experiment, &both, &[]).one_line_error(&["merged.json", "--force"]);
    merge(&experiment, &both, &["--force"]).success();
    assert_eq!(std::fs::read(dir.join("merged.json")).unwrap(), before);
    // A shard's folder holding a shard.json that learn did not write.
    std::fs::create_dir(dir.join("foreign")).unwrap();
    std::fs::write(dir.join("foreign/shard.json"), "mine").unwrap();
    let args = spread(
        &experiment,
        &experiment.data,
        &["--shard", "0/2", "--out", "foreign", "--force"],
    );
    let args: Vec<&str> = args.iter().map(String::as_str).collect();
    learn_in(&dir, &args).one_line_error(&["foreign/shard.json"]);
    assert_eq!(
        std::fs::read_to_string(dir.join("foreign/shard.json")).unwrap(),
        "mine"
    );
    // The merge's output may not be one of its shards.
    let run = learn_in(
        &dir,
        &[
            "merge",
            "--out",
            SmallExperiment::arg(&shards[0].join("shard.json")),
            SmallExperiment::arg(&shards[0]),
            SmallExperiment::arg(&shards[1]),
        ],
    );
    run.one_line_error(&["is the shard input, which this run reads"]);
}
