//! Merging shard results: the checks that they are one sweep's shards (same kind, configuration,
//! data, split and commit), that each holds only its own items, and that together they cover every
//! item exactly once. Every error names the shard file and field, or the items.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

use crate::experiment::WorkItem;
use learn::DataFile;
use serde::Serialize;

use super::{
    ShardFile, ShardProvenance, ShardSpec, SweepKind, configuration_sha256, content_sha256,
};
use crate::error::{EvaluationError, Result};

/// Shards merged: one sweep's context and every item's result in enumeration order.
#[derive(Clone, Debug)]
pub struct MergedSweep<C, R> {
    pub kind: SweepKind,
    pub context: C,
    pub items: Vec<WorkItem>,
    /// `results[i]` is the result of `items[i]`.
    pub results: Vec<R>,
    pub data_files: Vec<DataFile>,
    /// The commit every shard was computed at.
    pub git_commit: String,
    /// Each shard's file, part and provenance, in the order given.
    pub shards: Vec<(PathBuf, ShardSpec, ShardProvenance)>,
}

/// How many items an error lists before "and N more".
const LISTED_ITEMS: usize = 6;

/// Checks `shards` (each with the file it was read from) and merges them.
pub fn merge<C: Serialize, R: Serialize>(
    shards: Vec<(PathBuf, ShardFile<C, R>)>,
) -> Result<MergedSweep<C, R>> {
    let Some((first_path, first)) = shards.first() else {
        return Err(mismatch("no shard given".to_string()));
    };
    for (path, shard) in &shards {
        check_own_hash(path, shard)?;
        check_content_hash(path, shard)?;
        check_same_sweep(first_path, first, path, shard)?;
        check_own_items(path, shard)?;
    }
    check_coverage(&shards)?;
    let (_, first) = &shards[0];
    let (kind, items, data_files) = (first.kind, first.items.clone(), first.data_files.clone());
    let git_commit = first.provenance.git_commit.clone();
    let mut slots: Vec<Option<R>> = (0..items.len()).map(|_| None).collect();
    let mut context = None;
    let mut parts = Vec::with_capacity(shards.len());
    for (path, shard) in shards {
        for result in shard.results {
            slots[result.position] = Some(result.result);
        }
        context.get_or_insert(shard.context);
        parts.push((path, shard.shard, shard.provenance));
    }
    Ok(MergedSweep {
        kind,
        context: context.expect("at least one shard"),
        items,
        results: slots.into_iter().map(|r| r.expect("covered")).collect(),
        data_files,
        git_commit,
        shards: parts,
    })
}

fn mismatch(message: String) -> EvaluationError {
    EvaluationError::Mismatch {
        what: "the shards".to_string(),
        message,
    }
}

fn field_error(path: &Path, field: &str, message: String) -> EvaluationError {
    EvaluationError::Config {
        path: path.to_path_buf(),
        field: field.to_string(),
        message,
    }
}

/// The recorded configuration hash is that of the shard's own context and items.
fn check_own_hash<C: Serialize, R>(path: &Path, shard: &ShardFile<C, R>) -> Result<()> {
    let computed = configuration_sha256(shard.kind, &shard.context, &shard.items);
    if computed != shard.configuration_sha256 {
        return Err(field_error(
            path,
            "configuration_sha256",
            format!(
                "{} does not match the shard's context and items ({}): the file was changed \
                 after it was written",
                short(&shard.configuration_sha256),
                short(&computed)
            ),
        ));
    }
    Ok(())
}

/// The recorded content hash is that of every other field of the shard, its results and
/// provenance included.
fn check_content_hash<C: Serialize, R: Serialize>(
    path: &Path,
    shard: &ShardFile<C, R>,
) -> Result<()> {
    let computed = content_sha256(shard).map_err(|error| {
        field_error(
            path,
            "results",
            format!("cannot be hashed as JSON: {error}"),
        )
    })?;
    if computed != shard.content_sha256 {
        return Err(field_error(
            path,
            "content_sha256",
            format!(
                "{} does not match the shard's results and other fields ({}): the file was \
                 changed after it was written",
                short(&shard.content_sha256),
                short(&computed)
            ),
        ));
    }
    Ok(())
}

/// `shard` (at `path`) belongs to the sweep of `first` (at `first_path`).
fn check_same_sweep<C: Serialize, R>(
    first_path: &Path,
    first: &ShardFile<C, R>,
    path: &Path,
    shard: &ShardFile<C, R>,
) -> Result<()> {
    let other = first_path.display();
    if shard.kind != first.kind {
        return Err(field_error(
            path,
            "kind",
            format!(
                "a shard of {}, {other} of {}",
                shard.kind.command(),
                first.kind.command()
            ),
        ));
    }
    if shard.configuration_sha256 != first.configuration_sha256 {
        let difference = first_difference(&shard.context, &first.context)
            .map_or(String::new(), |at| format!("; they first differ at {at}"));
        return Err(field_error(
            path,
            "configuration_sha256",
            format!(
                "from a different configuration than {other} ({} against {}){difference}",
                short(&shard.configuration_sha256),
                short(&first.configuration_sha256)
            ),
        ));
    }
    if let Some(message) = data_difference(&shard.data_files, &first.data_files) {
        return Err(field_error(
            path,
            "data_files",
            format!("run on different data than {other}: {message}"),
        ));
    }
    if shard.shard.count != first.shard.count {
        return Err(field_error(
            path,
            "shard",
            format!(
                "{} splits the work into {} shards, {other} ({}) into {}",
                shard.shard, shard.shard.count, first.shard, first.shard.count
            ),
        ));
    }
    if shard.provenance.git_commit != first.provenance.git_commit {
        return Err(field_error(
            path,
            "provenance.git_commit",
            format!(
                "computed at commit {}, {other} at {}",
                shard.provenance.git_commit, first.provenance.git_commit
            ),
        ));
    }
    Ok(())
}

/// Every result of `shard` is one of its own items, recorded as the enumeration has it.
fn check_own_items<C, R>(path: &Path, shard: &ShardFile<C, R>) -> Result<()> {
    for (index, result) in shard.results.iter().enumerate() {
        let field = format!("results[{index}]");
        let Some(item) = shard.items.get(result.position) else {
            return Err(field_error(
                path,
                &field,
                format!(
                    "position {} is past the {} items of the sweep",
                    result.position,
                    shard.items.len()
                ),
            ));
        };
        if item != &result.item {
            return Err(field_error(
                path,
                &field,
                format!(
                    "item {} ({}) is recorded as '{}'",
                    result.position, item, result.item
                ),
            ));
        }
        if !shard.shard.runs(result.position) {
            return Err(field_error(
                path,
                &field,
                format!(
                    "item {} ({item}) is not one of shard {}'s",
                    result.position, shard.shard
                ),
            ));
        }
    }
    Ok(())
}

/// Every item is held by exactly one shard; otherwise an error naming the items held twice (and
/// where) or by none (and the shards to run).
fn check_coverage<C, R>(shards: &[(PathBuf, ShardFile<C, R>)]) -> Result<()> {
    let items = &shards[0].1.items;
    let mut owners: Vec<Option<usize>> = vec![None; items.len()];
    let mut twice: Vec<String> = Vec::new();
    for (index, (path, shard)) in shards.iter().enumerate() {
        for result in &shard.results {
            match owners[result.position] {
                Some(owner) => twice.push(format!(
                    "{} ({}) is in {} and {}",
                    result.position,
                    result.item,
                    shards[owner].0.display(),
                    path.display()
                )),
                None => owners[result.position] = Some(index),
            }
        }
    }
    if !twice.is_empty() {
        return Err(mismatch(format!(
            "items given twice (the same shard merged twice?): {}",
            listed(&twice)
        )));
    }
    let missing: Vec<usize> = (0..items.len()).filter(|&p| owners[p].is_none()).collect();
    if !missing.is_empty() {
        let count = shards[0].1.shard.count;
        let absent: BTreeSet<usize> = missing.iter().map(|p| p % count).collect();
        let absent: Vec<String> = absent.iter().map(|k| format!("{k}/{count}")).collect();
        let named: Vec<String> = missing
            .iter()
            .map(|&p| format!("{p} ({})", items[p]))
            .collect();
        return Err(mismatch(format!(
            "{} of {} items are in no shard given: {} (shards not given: {})",
            missing.len(),
            items.len(),
            listed(&named),
            absent.join(", ")
        )));
    }
    Ok(())
}

/// The first [`LISTED_ITEMS`] of `entries`, then how many more.
fn listed(entries: &[String]) -> String {
    let shown = entries[..entries.len().min(LISTED_ITEMS)].join("; ");
    match entries.len().saturating_sub(LISTED_ITEMS) {
        0 => shown,
        more => format!("{shown}; and {more} more"),
    }
}

/// A hash shortened for messages.
fn short(hash: &str) -> String {
    hash.chars().take(12).collect()
}

/// Where two data-file lists first differ, in words; `None` when they are the same.
fn data_difference(ours: &[DataFile], theirs: &[DataFile]) -> Option<String> {
    let map = |files: &[DataFile]| -> BTreeMap<PathBuf, String> {
        files
            .iter()
            .map(|f| (f.path.clone(), f.sha256.clone()))
            .collect()
    };
    let (ours, theirs) = (map(ours), map(theirs));
    for (path, sha) in &ours {
        match theirs.get(path) {
            None => return Some(format!("{} is read here only", path.display())),
            Some(other) if other != sha => {
                return Some(format!(
                    "{} has SHA-256 {} here and {} there",
                    path.display(),
                    short(sha),
                    short(other)
                ));
            }
            Some(_) => {}
        }
    }
    theirs
        .keys()
        .find(|path| !ours.contains_key(*path))
        .map(|path| format!("{} is read there only", path.display()))
}

/// The path (`context.config.seeds`) of the first place where two contexts differ.
fn first_difference<C: Serialize>(ours: &C, theirs: &C) -> Option<String> {
    let ours = serde_json::to_value(ours).ok()?;
    let theirs = serde_json::to_value(theirs).ok()?;
    value_difference(&ours, &theirs, "context")
}

fn value_difference(
    ours: &serde_json::Value,
    theirs: &serde_json::Value,
    at: &str,
) -> Option<String> {
    use serde_json::Value;
    match (ours, theirs) {
        (Value::Object(a), Value::Object(b)) => a
            .iter()
            .find_map(|(key, value)| match b.get(key) {
                Some(other) => value_difference(value, other, &format!("{at}.{key}")),
                None => Some(format!("{at}.{key}")),
            })
            .or_else(|| {
                b.keys()
                    .find(|key| !a.contains_key(*key))
                    .map(|key| format!("{at}.{key}"))
            }),
        (Value::Array(a), Value::Array(b)) if a.len() == b.len() => a
            .iter()
            .zip(b)
            .enumerate()
            .find_map(|(index, (x, y))| value_difference(x, y, &format!("{at}[{index}]"))),
        _ => (ours != theirs).then(|| at.to_string()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::experiment::Cells;
    use crate::shard::{SHARD_FORMAT, Sweep};
    use learn::Formulation;

    /// A sweep of five items whose context is `context`, over one data file.
    fn sweep(context: &str) -> Sweep<String> {
        let items = (0..5)
            .map(|seed| WorkItem {
                formulation: Formulation::Attitude,
                cells: Cells::Condition("35wind".to_string()),
                seed,
            })
            .collect();
        Sweep {
            kind: SweepKind::Ablations,
            context: context.to_string(),
            items,
            data_files: vec![DataFile {
                path: "experiment/a.csv".into(),
                sha256: "aa".to_string(),
            }],
        }
    }

    /// Shard `index` of `count` of `sweep`, each item's result its seed times ten.
    fn shard(
        sweep: &Sweep<String>,
        index: usize,
        count: usize,
    ) -> (PathBuf, ShardFile<String, u64>) {
        let spec = ShardSpec { index, count };
        let results = sweep
            .run(spec, |item| Ok(item.seed * 10))
            .expect("no item fails");
        let provenance = ShardProvenance {
            git_commit: "abc".to_string(),
            uncommitted_inputs: Some(false),
            host: None,
            threads: 1,
            stages: Vec::new(),
        };
        let path = PathBuf::from(format!("s{index}/shard.json"));
        let file = sweep.clone().shard_file(spec, results, provenance).unwrap();
        (path, file)
    }

    /// `file` with its content hash recomputed: edited consistently, so that the checks behind
    /// the hash are reached.
    fn rehashed(mut file: ShardFile<String, u64>) -> ShardFile<String, u64> {
        file.content_sha256 = content_sha256(&file).unwrap();
        file
    }

    fn error(shards: Vec<(PathBuf, ShardFile<String, u64>)>) -> String {
        merge(shards).unwrap_err().to_string()
    }

    #[test]
    fn shards_merge_into_every_result_in_enumeration_order() {
        let sweep = sweep("c");
        let shards = vec![
            shard(&sweep, 2, 3),
            shard(&sweep, 0, 3),
            shard(&sweep, 1, 3),
        ];
        assert_eq!(shards[1].1.format, SHARD_FORMAT);
        let merged = merge(shards).unwrap();
        assert_eq!(merged.results, [0, 10, 20, 30, 40]);
        assert_eq!(merged.items, sweep.items);
        assert_eq!(merged.context, "c");
        assert_eq!(merged.git_commit, "abc");
        let whole = merge(vec![shard(&sweep, 0, 1)]).unwrap();
        assert_eq!(whole.results, merged.results);
    }

    #[test]
    fn missing_and_duplicated_items_are_named() {
        let sweep = sweep("c");
        let message = error(vec![shard(&sweep, 0, 3), shard(&sweep, 2, 3)]);
        assert_eq!(
            message,
            "the shards: 2 of 5 items are in no shard given: 1 (attitude 35wind seed 1); \
             4 (attitude 35wind seed 4) (shards not given: 1/3)"
        );
        let message = error(vec![
            shard(&sweep, 0, 2),
            shard(&sweep, 1, 2),
            shard(&sweep, 1, 2),
        ]);
        assert!(
            message.starts_with(
                "the shards: items given twice (the same shard merged twice?): \
                 1 (attitude 35wind seed 1) is in s1/shard.json and s1/shard.json; 3 ("
            ),
            "{message}"
        );
    }

    #[test]
    fn shards_of_other_configurations_data_splits_or_commits_are_refused() {
        let ours = sweep("c");
        let (path, first) = shard(&ours, 0, 2);
        let message = error(vec![
            (path.clone(), first.clone()),
            shard(&sweep("d"), 1, 2),
        ]);
        assert!(
            message.starts_with("s1/shard.json: configuration_sha256: from a different configuration than s0/shard.json (")
                && message.ends_with("they first differ at context"),
            "{message}"
        );
        let mut other_data = ours.clone();
        other_data.data_files[0].sha256 = "bb".to_string();
        let message = error(vec![
            (path.clone(), first.clone()),
            shard(&other_data, 1, 2),
        ]);
        assert_eq!(
            message,
            "s1/shard.json: data_files: run on different data than s0/shard.json: \
             experiment/a.csv has SHA-256 bb here and aa there"
        );
        let message = error(vec![(path.clone(), first.clone()), shard(&ours, 1, 3)]);
        assert_eq!(
            message,
            "s1/shard.json: shard: 1/3 splits the work into 3 shards, s0/shard.json (0/2) into 2"
        );
        let mut later = shard(&ours, 1, 2);
        later.1.provenance.git_commit = "def".to_string();
        let later = (later.0, rehashed(later.1));
        let message = error(vec![(path.clone(), first.clone()), later]);
        assert_eq!(
            message,
            "s1/shard.json: provenance.git_commit: computed at commit def, s0/shard.json at abc"
        );
        let mut ablations = shard(&ours, 1, 2);
        ablations.1.kind = SweepKind::Reproduce;
        let message = error(vec![(path, first), ablations]);
        assert!(
            message.starts_with("s1/shard.json: configuration_sha256: "),
            "{message}"
        );
    }

    #[test]
    fn an_edited_shard_is_refused() {
        let sweep = sweep("c");
        let (path, mut edited) = shard(&sweep, 0, 1);
        edited.context = "changed".to_string();
        let message = error(vec![(path.clone(), edited)]);
        assert!(
            message.starts_with("s0/shard.json: configuration_sha256: ")
                && message.contains("the file was changed after it was written"),
            "{message}"
        );
        let (_, mut foreign) = shard(&sweep, 0, 2);
        foreign.results[1].position = 1;
        let message = error(vec![(path.clone(), rehashed(foreign))]);
        assert_eq!(
            message,
            "s0/shard.json: results[1]: item 1 (attitude 35wind seed 1) is recorded as 'attitude 35wind seed 2'"
        );
        let (_, mut stray) = shard(&sweep, 0, 2);
        stray.results[1].position = 1;
        stray.results[1].item = sweep.items[1].clone();
        let message = error(vec![(path.clone(), rehashed(stray))]);
        assert_eq!(
            message,
            "s0/shard.json: results[1]: item 1 (attitude 35wind seed 1) is not one of shard 0/2's"
        );
        let (_, mut past) = shard(&sweep, 0, 2);
        past.results[0].position = 9;
        let message = error(vec![(path, rehashed(past))]);
        assert_eq!(
            message,
            "s0/shard.json: results[0]: position 9 is past the 5 items of the sweep"
        );
    }

    #[test]
    fn an_edited_result_or_provenance_is_refused_by_its_hash() {
        let sweep = sweep("c");
        let (path, written) = shard(&sweep, 0, 1);
        assert!(merge(vec![(path.clone(), written.clone())]).is_ok());
        let mut result = written.clone();
        result.results[2].result += 1;
        let mut host = written.clone();
        host.provenance.host = Some("elsewhere".to_string());
        let mut threads = written;
        threads.provenance.threads = 64;
        for edited in [result, host, threads] {
            let message = error(vec![(path.clone(), edited)]);
            assert!(
                message.starts_with("s0/shard.json: content_sha256: ")
                    && message.ends_with("the file was changed after it was written"),
                "{message}"
            );
        }
    }
}
