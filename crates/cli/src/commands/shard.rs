//! What the sharded commands share: `--shard K/N` and the shard's output set (`--out DIR` holding
//! `shard.json` only).

use std::path::{Path, PathBuf};

use evaluation::{SHARD_FILE, ShardFile, ShardSpec};
use output_set::{Existing, OutputSet, Staged};
use serde::Serialize;

/// `--shard K/N`: a clap value parser whose message says what is wrong.
pub fn parse_shard(text: &str) -> Result<ShardSpec, String> {
    text.parse()
}

/// The help of `--shard`.
pub const SHARD_HELP: &str = "Run only shard K of N (K from 0): the work items whose position is K \
    modulo N, written to --out DIR as shard.json (nothing else); `learn merge` puts the shards \
    together. See docs/cluster.md";

/// A shard's output set: `out/shard.json`, recorded as written by `producer` (distinct from the
/// unsharded command's, so neither ever removes the other's files), and the run's inputs.
pub struct ShardOutputs {
    set: OutputSet,
    folder: output_set::FolderId,
    out: PathBuf,
}

impl ShardOutputs {
    /// Plans `out/shard.json`; `inputs` (what, path) may not be outputs. Checked, not created.
    pub fn plan(
        producer: &str,
        out: &Path,
        force: bool,
        inputs: &[(String, PathBuf)],
    ) -> anyhow::Result<Self> {
        let mut set = OutputSet::new(producer);
        for (what, path) in inputs {
            set.input(format!("the {what} input"), path);
        }
        let folder = set.folder(out, "--out", Existing::from_force(force));
        set.file_in(folder, SHARD_FILE);
        set.check()?;
        Ok(Self {
            set,
            folder,
            out: out.to_path_buf(),
        })
    }

    /// Locks and stages the folder (before any work).
    pub fn prepare(self) -> anyhow::Result<StagedShard> {
        Ok(StagedShard {
            staged: self.set.prepare()?,
            folder: self.folder,
            out: self.out,
        })
    }
}

/// A shard's output folder, staged.
pub struct StagedShard {
    staged: Staged,
    folder: output_set::FolderId,
    out: PathBuf,
}

impl StagedShard {
    /// Writes `file` and moves it into place; prints where.
    pub fn commit<C: Serialize, R: Serialize>(self, file: &ShardFile<C, R>) -> anyhow::Result<()> {
        let dir = self.staged.dir(self.folder).to_path_buf();
        super::staged_write(&self.staged, || evaluation::write_shard(file, &dir))?;
        self.staged.commit()?;
        note!(
            "shard {}: {} of {} items, written to {}",
            file.shard,
            file.results.len(),
            file.items.len(),
            self.out.join(SHARD_FILE).display()
        );
        Ok(())
    }
}
