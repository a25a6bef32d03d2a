//! The paper's published numbers (`paper/published.json`).

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use crate::error::{Result, read_json};
use crate::table::MethodPair;

/// `{"source": "...", "tables": {"translational": {"35wind": {"sindy": {...}, "learn": {...}}}}}`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PublishedTables {
    /// Where the numbers come from.
    pub source: String,
    /// Table name, then the condition as the paper prints it.
    pub tables: BTreeMap<String, BTreeMap<String, MethodPair>>,
    /// The file the numbers were read from (empty when built in code), for error messages.
    #[serde(skip)]
    pub path: PathBuf,
}

impl PublishedTables {
    /// Reads `published.json`.
    pub fn load(path: &Path) -> Result<Self> {
        let published: Self = read_json(path)?;
        Ok(Self {
            path: path.to_path_buf(),
            ..published
        })
    }

    /// The published numbers of one cell row, if the paper has them.
    pub fn get(&self, table: &str, condition: &str) -> Option<&MethodPair> {
        self.tables.get(table)?.get(condition)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reads_the_committed_file() {
        let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../paper/published.json");
        let published = PublishedTables::load(&path).unwrap();
        let cell = published.get("attitude", "70psin20").unwrap();
        assert_eq!(cell.learn.generalisation, 0.493);
        assert_eq!(cell.sindy.adaptation, 0.578);
        assert!(published.get("attitude", "200wind").is_none());
    }
}
