//! Sharded runs (issue 20): `learn reproduce`, `learn ablations` and `learn meta-train
//! --seed-spread` split into 3 shards run as parallel processes (beside the unsharded run), then
//! `learn merge`d: every file the unsharded run writes is written again byte for byte, but
//! `timings.json` (wall times, hosts, threads: provenance). On a small generated experiment
//! (`common::sweep`), so no real flight is needed and each run takes about a second.

mod common;

use std::path::{Path, PathBuf};

use common::sweep::{SmallExperiment, files_under, learn_at_once, small_experiment};
use common::{learn_in, scratch};

/// The only file a merge may write differently from the unsharded run: wall times and hosts.
const PROVENANCE_ONLY: [&str; 1] = ["timings.json"];

/// `args` as owned strings.
fn owned(args: &[&str]) -> Vec<String> {
    args.iter().map(|a| a.to_string()).collect()
}

/// `learn --quiet --data DATA <command…>` of `experiment`.
fn command(experiment: &SmallExperiment, rest: &[&str]) -> Vec<String> {
    let mut args = owned(&["--quiet", "--data", SmallExperiment::arg(&experiment.data)]);
    args.extend(owned(rest));
    args
}

/// The unsharded run (`whole`) and shards 0/3, 1/3, 2/3 of `base` at the same time; each shard
/// into `shards/K`; `whole` are the unsharded run's own options. Returns the shard folders.
fn whole_and_three_shards(
    experiment: &SmallExperiment,
    base: &[&str],
    whole: &[&str],
) -> Vec<PathBuf> {
    let mut runs = vec![command(experiment, &[base, whole].concat())];
    let dirs: Vec<PathBuf> = (0..3)
        .map(|k| experiment.dir.join(format!("shards/{k}")))
        .collect();
    for (k, dir) in dirs.iter().enumerate() {
        let shard = format!("{k}/3");
        let out = SmallExperiment::arg(dir);
        runs.push(command(
            experiment,
            &[base, &["--shard", &shard, "--out", out]].concat(),
        ));
    }
    for run in learn_at_once(&experiment.dir, &runs) {
        run.success();
    }
    for dir in &dirs {
        let written: Vec<PathBuf> = files_under(dir, &[]).into_keys().collect();
        assert_eq!(
            written,
            [
                PathBuf::from(".learn-outputs.json"),
                PathBuf::from("shard.json")
            ],
            "a shard writes its result only"
        );
    }
    dirs
}

/// `learn merge` of `shards` (in the order 2, 0, 1) with `options`; must succeed.
fn merge(experiment: &SmallExperiment, shards: &[PathBuf], options: &[&str]) -> common::Run {
    let mut args = owned(&["merge"]);
    args.extend(owned(options));
    for k in [2, 0, 1] {
        args.push(SmallExperiment::arg(&shards[k]).to_string());
    }
    let args: Vec<&str> = args.iter().map(String::as_str).collect();
    let run = learn_in(&experiment.dir, &args);
    run.success();
    run
}

/// The same files with the same bytes under both folders, but [`PROVENANCE_ONLY`].
fn assert_same_files(whole: &Path, merged: &Path) {
    let whole = files_under(whole, &PROVENANCE_ONLY);
    let merged = files_under(merged, &PROVENANCE_ONLY);
    assert!(whole.len() > 2, "the run wrote {} files", whole.len());
    let names = |files: &std::collections::BTreeMap<PathBuf, Vec<u8>>| -> Vec<PathBuf> {
        files.keys().cloned().collect()
    };
    assert_eq!(names(&whole), names(&merged));
    for (file, bytes) in &whole {
        assert!(&merged[file] == bytes, "{} differs", file.display());
    }
}

#[test]
fn reproduce_in_three_parallel_shards_merges_into_the_unsharded_run_byte_for_byte() {
    let dir = scratch("shard-reproduce");
    let experiment = small_experiment(&dir);
    let run = SmallExperiment::arg(&experiment.run);
    let root = SmallExperiment::arg(&dir);
    let base = ["reproduce", "--root", root, "--config", run];
    std::fs::create_dir_all(dir.join("whole")).unwrap();
    std::fs::create_dir_all(dir.join("merged")).unwrap();
    let readme = "# Results\n\n<!-- tables:begin -->\n<!-- tables:end -->\n";
    for folder in ["whole", "merged"] {
        std::fs::write(dir.join(folder).join("README.md"), readme).unwrap();
    }
    let whole = [
        "--out",
        "whole",
        "--latex-dir",
        "whole/latex",
        "--readme",
        "whole/README.md",
    ];
    let shards = whole_and_three_shards(&experiment, &base, &whole);
    let options = [
        "--out",
        "merged",
        "--latex-dir",
        "merged/latex",
        "--readme",
        "merged/README.md",
    ];
    let merged = merge(&experiment, &shards, &options);
    assert!(merged.stdout.contains("| gust |"), "{}", merged.stdout);
    assert_same_files(&dir.join("whole"), &dir.join("merged"));
    let summary = std::fs::read_to_string(dir.join("merged/summary.json")).unwrap();
    assert!(
        summary.contains("\"seeds\": [\n      1,\n      2\n    ]"),
        "two seeds"
    );
    let timings = std::fs::read_to_string(dir.join("merged/timings.json")).unwrap();
    assert!(timings.contains("shard 2/3 on "), "{timings}");
}

#[test]
fn ablations_in_three_parallel_shards_merge_into_the_unsharded_run_byte_for_byte() {
    let dir = scratch("shard-ablations");
    let experiment = small_experiment(&dir);
    let variants = SmallExperiment::arg(&experiment.variants);
    let root = SmallExperiment::arg(&dir);
    let base = ["ablations", "--root", root, "--config", variants];
    let shards = whole_and_three_shards(&experiment, &base, &["--out", "whole"]);
    let merged = merge(&experiment, &shards, &["--out", "merged"]);
    assert!(merged.stdout.contains("# Ablations"), "{}", merged.stdout);
    assert_same_files(&dir.join("whole"), &dir.join("merged"));
    // The bagged variant's figures (with their band) are among the files compared.
    let figures = files_under(&dir.join("merged/figures"), &[]);
    assert_eq!(figures.len(), 6, "{:?}", figures.keys());
}

#[test]
fn the_seed_spread_in_three_parallel_shards_merges_into_the_unsharded_file_byte_for_byte() {
    let dir = scratch("shard-spread");
    let experiment = small_experiment(&dir);
    // The paper's protocol: one model per formulation and seed serves both conditions.
    let base = [
        "meta-train",
        "--config",
        SmallExperiment::arg(&experiment.learn),
        "--conditions",
        SmallExperiment::arg(&experiment.conditions),
        "--protocol",
        "paper",
        "--seed-spread",
    ];
    let shards = whole_and_three_shards(&experiment, &base, &["--spread-out", "whole.json"]);
    merge(&experiment, &shards, &["--out", "merged.json"]);
    let whole = std::fs::read(dir.join("whole.json")).unwrap();
    assert!(whole == std::fs::read(dir.join("merged.json")).unwrap());
    let spread: serde_json::Value = serde_json::from_slice(&whole).unwrap();
    assert_eq!(spread["protocol"], "paper");
    assert_eq!(spread["cells"].as_array().unwrap().len(), 6);
}
