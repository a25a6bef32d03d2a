//! Sharded sweeps: the work of `learn reproduce`, `learn ablations` and the seed spread split over
//! processes or machines by an existing scheduler (SLURM job arrays, Kubernetes Indexed Jobs,
//! `xargs -P`), then merged.
//!
//! A [`Sweep`] is a run's work enumerated once, in a fixed order, as [`WorkItem`]s (one
//! meta-training with its seed and the cells it serves), with the [`Sweep::context`]: what
//! rendering needs besides the items' results (configuration, published numbers, file hashes).
//! The unsharded run executes every item and renders; shard `K/N` ([`ShardSpec`]) executes the
//! items whose position is ≡ K (mod N) and writes a [`ShardFile`] (`shard.json`) with the
//! configuration's hash, the data files' hashes, the item list, each item's result and the hash of
//! all of it ([`ShardFile::content_sha256`]); [`merge`] checks that no shard was edited, and that shards belong together and cover every item once, and hands the
//! results, in enumeration order, to the same rendering code. Each item depends on its own seed
//! only, so a merged sweep is bit-identical to the unsharded one.

mod merge;

use std::fmt;
use std::path::{Path, PathBuf};
use std::str::FromStr;

use crate::experiment::WorkItem;
use learn::DataFile;
use rayon::prelude::*;
use serde::de::DeserializeOwned;
use serde::{Deserialize, Serialize};

use crate::error::{EvaluationError, Result};
use crate::summary::StageTiming;

pub use merge::{MergedSweep, merge};

/// The file a shard writes in its `--out` folder.
pub const SHARD_FILE: &str = "shard.json";
/// The format tag of [`SHARD_FILE`].
pub const SHARD_FORMAT: &str = "learn-shard/2";
/// Formats of earlier versions, refused with the reason: `learn-shard/1` had no hash of its
/// results, so an edited result could not be told from a computed one.
const EARLIER_FORMATS: [&str; 1] = ["learn-shard/1"];

/// Shard `index` of `count` (`K/N` on the command line, K from 0): the items whose position in
/// the sweep's enumeration is ≡ K (mod N).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ShardSpec {
    pub index: usize,
    pub count: usize,
}

impl ShardSpec {
    /// The whole sweep as one shard (what an unsharded run executes).
    pub const WHOLE: ShardSpec = ShardSpec { index: 0, count: 1 };

    /// Whether this shard runs the item at `position` of the enumeration.
    pub fn runs(&self, position: usize) -> bool {
        position % self.count == self.index
    }

    /// The positions this shard runs among `total` items.
    pub fn positions(&self, total: usize) -> Vec<usize> {
        (self.index..total).step_by(self.count).collect()
    }
}

impl FromStr for ShardSpec {
    type Err = String;

    /// `K/N` with 0 ≤ K < N; the message says what is wrong otherwise.
    fn from_str(text: &str) -> std::result::Result<Self, String> {
        let Some((index, count)) = text.split_once('/') else {
            return Err(format!(
                "'{text}' is not K/N (shard K of N, K counted from 0, e.g. 0/4)"
            ));
        };
        let number = |part: &str, name: &str| {
            part.trim().parse::<usize>().map_err(|_| {
                format!("{name} = '{part}' in '{text}' is not a whole number (K/N, e.g. 0/4)")
            })
        };
        let (index, count) = (number(index, "K")?, number(count, "N")?);
        if count == 0 {
            return Err(format!(
                "N = 0 in '{text}': the work is split into at least 1 shard"
            ));
        }
        if index >= count {
            return Err(format!(
                "K = {index} is not below N = {count} in '{text}': shards are numbered 0 to N − 1"
            ));
        }
        Ok(Self { index, count })
    }
}

impl fmt::Display for ShardSpec {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}/{}", self.index, self.count)
    }
}

/// Which command's work a sweep is.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum SweepKind {
    Reproduce,
    Ablations,
    SeedSpread,
}

impl SweepKind {
    /// The command that runs (and shards) this sweep.
    pub fn command(self) -> &'static str {
        match self {
            Self::Reproduce => "learn reproduce",
            Self::Ablations => "learn ablations",
            Self::SeedSpread => "learn meta-train --seed-spread",
        }
    }
}

/// One item's result with its position in the enumeration.
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ItemResult<R> {
    pub position: usize,
    pub item: WorkItem,
    pub result: R,
}

/// Where and how a shard ran: what may differ between two runs of the same work.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ShardProvenance {
    /// The last commit that changed an input of the run (see [`crate::git_commit`]).
    pub git_commit: String,
    /// Tracked inputs differed from `git_commit` (`None`: not a checkout).
    pub uncommitted_inputs: Option<bool>,
    pub host: Option<String>,
    /// Rayon worker threads.
    pub threads: usize,
    pub stages: Vec<StageTiming>,
}

impl ShardProvenance {
    /// This process's provenance for a run of the checkout at `root` with `stages`.
    pub fn here(root: &Path, stages: Vec<StageTiming>) -> Self {
        Self {
            git_commit: crate::git_commit(root),
            uncommitted_inputs: crate::uncommitted_inputs(root),
            host: host_name(),
            threads: crate::worker_threads(),
            stages,
        }
    }
}

/// The machine's name, if it can be read.
fn host_name() -> Option<String> {
    std::env::var("HOSTNAME")
        .ok()
        .or_else(|| std::fs::read_to_string("/proc/sys/kernel/hostname").ok())
        .map(|name| name.trim().to_string())
        .filter(|name| !name.is_empty())
}

/// `shard.json`: one shard's results and everything needed to check and merge it.
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ShardFile<C, R> {
    /// Always [`SHARD_FORMAT`].
    pub format: String,
    pub kind: SweepKind,
    /// [`Sweep::configuration_sha256`]: the same in every shard of one sweep.
    pub configuration_sha256: String,
    /// Every flight the sweep reads (relative to the data directory), with its SHA-256.
    pub data_files: Vec<DataFile>,
    pub shard: ShardSpec,
    /// Every item of the sweep, in enumeration order (not only this shard's).
    pub items: Vec<WorkItem>,
    pub context: C,
    /// This shard's items' results, by position.
    pub results: Vec<ItemResult<R>>,
    pub provenance: ShardProvenance,
    /// The SHA-256 of every other field ([`content_sha256`]): the results, the provenance and
    /// everything else a merge renders, so that a shard edited after it was written is refused.
    pub content_sha256: String,
}

/// Every field of a [`ShardFile`] but its `content_sha256`, as it is written: what that hash
/// covers.
#[derive(Serialize)]
struct ShardContent<'a, C, R> {
    format: &'a str,
    kind: SweepKind,
    configuration_sha256: &'a str,
    data_files: &'a [DataFile],
    shard: ShardSpec,
    items: &'a [WorkItem],
    context: &'a C,
    results: &'a [ItemResult<R>],
    provenance: &'a ShardProvenance,
}

/// The SHA-256 of the compact JSON of every field of `file` but `content_sha256` (floats written
/// as the shortest decimal that reads back to the same bits, so a shard read back hashes the
/// same); an error if a value cannot be written as JSON.
pub(crate) fn content_sha256<C: Serialize, R: Serialize>(
    file: &ShardFile<C, R>,
) -> std::result::Result<String, serde_json::Error> {
    let content = ShardContent {
        format: &file.format,
        kind: file.kind,
        configuration_sha256: &file.configuration_sha256,
        data_files: &file.data_files,
        shard: file.shard,
        items: &file.items,
        context: &file.context,
        results: &file.results,
        provenance: &file.provenance,
    };
    Ok(data::bytes_sha256(
        serde_json::to_string(&content)?.as_bytes(),
    ))
}

/// A run's work: its items in enumeration order and what rendering needs besides their results.
#[derive(Clone, Debug)]
pub struct Sweep<C> {
    pub kind: SweepKind,
    /// Derived from the configuration only (and the hashes of the files it names).
    pub context: C,
    pub items: Vec<WorkItem>,
    /// Every flight read, as [`ShardFile::data_files`].
    pub data_files: Vec<DataFile>,
}

impl<C: Serialize> Sweep<C> {
    /// The SHA-256 of the sweep's kind, context and items: equal for two runs of the same
    /// configuration files (by content) and options.
    pub fn configuration_sha256(&self) -> String {
        configuration_sha256(self.kind, &self.context, &self.items)
    }

    /// Runs the items of `shard` in parallel with `run_item`; results in enumeration order.
    pub fn run<R: Send>(
        &self,
        shard: ShardSpec,
        run_item: impl Fn(&WorkItem) -> Result<R> + Sync,
    ) -> Result<Vec<ItemResult<R>>>
    where
        C: Sync,
    {
        shard
            .positions(self.items.len())
            .into_par_iter()
            .map(|position| {
                let item = &self.items[position];
                Ok(ItemResult {
                    position,
                    item: item.clone(),
                    result: run_item(item)?,
                })
            })
            .collect()
    }

    /// The shard file of `shard` with its `results`, hashed; an error if a result cannot be
    /// written as JSON.
    pub fn shard_file<R: Serialize>(
        self,
        shard: ShardSpec,
        results: Vec<ItemResult<R>>,
        provenance: ShardProvenance,
    ) -> Result<ShardFile<C, R>> {
        let mut file = ShardFile {
            format: SHARD_FORMAT.to_string(),
            kind: self.kind,
            configuration_sha256: self.configuration_sha256(),
            data_files: self.data_files,
            shard,
            items: self.items,
            context: self.context,
            results,
            provenance,
            content_sha256: String::new(),
        };
        file.content_sha256 = content_sha256(&file).map_err(|error| EvaluationError::Mismatch {
            what: format!("shard {shard}"),
            message: format!("cannot be written as JSON: {error}"),
        })?;
        Ok(file)
    }
}

fn configuration_sha256<C: Serialize>(kind: SweepKind, context: &C, items: &[WorkItem]) -> String {
    let document = serde_json::json!({
        "format": SHARD_FORMAT,
        "kind": kind,
        "context": context,
        "items": items,
    });
    data::bytes_sha256(document.to_string().as_bytes())
}

/// Writes `file` as `dir/shard.json` (compact JSON: the traces dominate its size).
pub fn write_shard<C: Serialize, R: Serialize>(file: &ShardFile<C, R>, dir: &Path) -> Result<()> {
    let mut text = serde_json::to_string(file).map_err(|error| EvaluationError::Mismatch {
        what: format!("shard {}", file.shard),
        message: format!("cannot be written as JSON: {error}"),
    })?;
    text.push('\n');
    crate::error::write_text(&dir.join(SHARD_FILE), &text)
}

/// A shard result read but not yet interpreted: its file, its kind and its JSON.
pub struct ShardDocument {
    pub path: PathBuf,
    pub kind: SweepKind,
    value: serde_json::Value,
}

/// Reads `dir/shard.json` (or `dir` itself when it is a file) and its kind; a folder without one,
/// or a file that is not a shard result, is an error naming it.
pub fn read_shard(dir: &Path) -> Result<ShardDocument> {
    let path = if dir.is_dir() {
        dir.join(SHARD_FILE)
    } else {
        dir.to_path_buf()
    };
    let not_a_shard = |message: String| EvaluationError::Config {
        path: dir.to_path_buf(),
        field: "shard".to_string(),
        message,
    };
    if !dir.exists() {
        return Err(not_a_shard("no such folder".to_string()));
    }
    if dir.is_dir() && !path.exists() {
        return Err(not_a_shard(format!(
            "not a shard folder: it has no {SHARD_FILE} (written by learn reproduce, ablations \
             or meta-train --seed-spread with --shard K/N --out DIR)"
        )));
    }
    let text =
        bounded_read::read_text(&path, bounded_read::InputKind::ShardResult).map_err(|source| {
            EvaluationError::Io {
                path: path.clone(),
                source,
            }
        })?;
    let value: serde_json::Value =
        bounded_read::json::from_str(&text).map_err(|error| EvaluationError::json(&path, error))?;
    let format = value.get("format").and_then(|f| f.as_str());
    if let Some(earlier) = format.filter(|f| EARLIER_FORMATS.contains(f)) {
        return Err(EvaluationError::Config {
            path,
            field: "format".to_string(),
            message: format!(
                "a shard of an earlier learn ('{earlier}', whose results no hash covers; this \
                 learn reads '{SHARD_FORMAT}'): run the shard again"
            ),
        });
    }
    if format != Some(SHARD_FORMAT) {
        let found = format.map_or("no format".to_string(), |f| format!("format '{f}'"));
        return Err(EvaluationError::Config {
            path,
            field: "format".to_string(),
            message: format!("not a shard result ({found}; a shard has '{SHARD_FORMAT}')"),
        });
    }
    let kind = bounded_read::json::from_value(value.get("kind").cloned().unwrap_or_default())
        .map_err(|error| EvaluationError::Config {
            path: path.clone(),
            field: "kind".to_string(),
            message: error.message,
        })?;
    Ok(ShardDocument { path, kind, value })
}

impl ShardDocument {
    /// The shard as the results of a sweep with context `C` and item results `R`.
    pub fn typed<C, R>(self) -> Result<(PathBuf, ShardFile<C, R>)>
    where
        C: DeserializeOwned + Serialize,
        R: DeserializeOwned + Serialize,
    {
        let file = bounded_read::json::from_value(self.value)
            .map_err(|error| EvaluationError::json(&self.path, error))?;
        Ok((self.path, file))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shards_are_read_as_k_of_n() {
        let spec: ShardSpec = "1/3".parse().unwrap();
        assert_eq!(spec, ShardSpec { index: 1, count: 3 });
        assert_eq!(spec.to_string(), "1/3");
        assert_eq!(spec.positions(8), [1, 4, 7]);
        assert!(spec.runs(4) && !spec.runs(5));
        assert_eq!(ShardSpec::WHOLE.positions(3), [0, 1, 2]);
        let refused = [
            (
                "3/3",
                "K = 3 is not below N = 3 in '3/3': shards are numbered 0 to N − 1",
            ),
            (
                "0/0",
                "N = 0 in '0/0': the work is split into at least 1 shard",
            ),
            (
                "2",
                "'2' is not K/N (shard K of N, K counted from 0, e.g. 0/4)",
            ),
            (
                "-1/3",
                "K = '-1' in '-1/3' is not a whole number (K/N, e.g. 0/4)",
            ),
            (
                "1/x",
                "N = 'x' in '1/x' is not a whole number (K/N, e.g. 0/4)",
            ),
            (
                "1/2/3",
                "N = '2/3' in '1/2/3' is not a whole number (K/N, e.g. 0/4)",
            ),
        ];
        for (text, message) in refused {
            assert_eq!(text.parse::<ShardSpec>().unwrap_err(), message, "{text}");
        }
    }

    #[test]
    fn results_read_back_bit_for_bit() {
        let values = vec![
            0.1 + 0.2,
            1.0 / 3.0,
            -2.5e-300,
            f64::MIN_POSITIVE / 3.0,
            f64::MAX,
            0.123_456_789_012_345_67,
        ];
        let sweep = Sweep {
            kind: SweepKind::Reproduce,
            context: "c".to_string(),
            items: vec![WorkItem {
                formulation: learn::Formulation::Full,
                cells: crate::experiment::Cells::Every,
                seed: 7,
            }],
            data_files: Vec::new(),
        };
        let results = sweep.run(ShardSpec::WHOLE, |_| Ok(values.clone())).unwrap();
        let provenance = ShardProvenance::here(Path::new("."), Vec::new());
        let file = sweep
            .shard_file(ShardSpec::WHOLE, results, provenance)
            .unwrap();
        let scratch = tempfile::tempdir().unwrap();
        let dir = scratch.path().join("shard");
        write_shard(&file, &dir).unwrap();
        let (path, read) = read_shard(&dir)
            .unwrap()
            .typed::<String, Vec<f64>>()
            .unwrap();
        assert_eq!(path, dir.join(SHARD_FILE));
        let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        assert_eq!(bits(&read.results[0].result), bits(&values));
        assert_eq!(read.configuration_sha256, file.configuration_sha256);
    }

    #[test]
    fn a_folder_or_file_that_is_not_a_shard_is_named() {
        let scratch = tempfile::tempdir().unwrap();
        let dir = scratch.path().to_path_buf();
        let message = read_shard(&dir).err().unwrap().to_string();
        assert!(
            message.starts_with(&format!("{}: shard: not a shard folder", dir.display())),
            "{message}"
        );
        std::fs::write(dir.join(SHARD_FILE), r#"{"format": "learn-results/1"}"#).unwrap();
        let message = read_shard(&dir).err().unwrap().to_string();
        assert!(
            message.ends_with("shard.json: format: not a shard result (format 'learn-results/1'; a shard has 'learn-shard/2')"),
            "{message}"
        );
        std::fs::write(dir.join(SHARD_FILE), r#"{"format": "learn-shard/1"}"#).unwrap();
        let message = read_shard(&dir).err().unwrap().to_string();
        assert!(
            message.ends_with(
                "shard.json: format: a shard of an earlier learn ('learn-shard/1', whose \
                 results no hash covers; this learn reads 'learn-shard/2'): run the shard again"
            ),
            "{message}"
        );
        std::fs::write(
            dir.join(SHARD_FILE),
            r#"{"format": "learn-shard/2", "kind": "paper"}"#,
        )
        .unwrap();
        let message = read_shard(&dir).err().unwrap().to_string();
        assert!(
            message.contains("shard.json: kind: unknown variant `paper`"),
            "{message}"
        );
    }
}
