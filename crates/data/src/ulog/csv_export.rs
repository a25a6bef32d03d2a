//! A PX4 log exported to CSV (pyulog's `ulog2csv`): one file per topic instance,
//! `<log>_<topic>_<k>.csv`, each with its own `timestamp` column (µs) and the topic's fields by
//! their ULog names (`q[0]`, `xyz[2]`, `control[3]`). The columns a layout names
//! (`topic.field`, `topic[k].field`) are joined on one topic's clock exactly as from the `.ulg`
//! ([`super::aligned_table`]): held as of each row, never interpolated.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use crate::cells::bad_cell;
use crate::error::{DataError, Result};
use crate::table::TextTable;

use super::AlignedTable;
use super::aligned::{TopicClock, column_name, join, topic_name};

/// One topic instance's file: its time stamps (µs) and the cells of the fields read.
struct TopicFile {
    path: PathBuf,
    timestamps: Vec<u64>,
    fields: BTreeMap<String, Vec<f64>>,
}

/// The columns `columns` of the export in folder `dir` on the clock of topic `base` (`name` or
/// `name[k]`; the first column's topic when `None`), with the time (s, on the table's clock) of the
/// earliest sample of the topics read: an export keeps no log start.
pub fn aligned_export_table(
    dir: &Path,
    base: Option<&str>,
    columns: &[&str],
) -> Result<(AlignedTable, f64)> {
    let bad = |field: &str, message: String| DataError::Config {
        path: dir.to_path_buf(),
        field: field.to_string(),
        message,
    };
    let mut wanted: BTreeMap<(String, u8), Vec<String>> = BTreeMap::new();
    let mut names = Vec::with_capacity(columns.len());
    for &column in columns {
        let name = column_name(column).ok_or_else(|| {
            bad(
                column,
                "is a directory, read as a PX4 CSV export, whose columns are named topic.field or topic[k].field".into(),
            )
        })?;
        let key = (name.topic.to_string(), name.instance);
        wanted
            .entry(key.clone())
            .or_default()
            .push(name.field.into());
        names.push((key, name.field));
    }
    let base_key = match base {
        Some(text) => {
            let (topic, instance) =
                topic_name(text).ok_or_else(|| bad(text, "not a topic name".into()))?;
            (topic.to_string(), instance)
        }
        None => names
            .first()
            .map(|(key, _)| key.clone())
            .ok_or_else(|| bad("columns", "no column named".into()))?,
    };
    wanted.entry(base_key.clone()).or_default();
    let entries = std::fs::read_dir(dir).map_err(|source| DataError::Io {
        path: dir.to_path_buf(),
        source,
    })?;
    let listed: Vec<PathBuf> = entries.filter_map(|e| e.ok().map(|e| e.path())).collect();
    let mut files = BTreeMap::new();
    for ((topic, instance), fields) in &wanted {
        let path = topic_file(dir, &listed, topic, *instance)?;
        files.insert((topic.clone(), *instance), read_topic(&path, fields)?);
    }
    let clock = |key: &(String, u8)| TopicClock {
        label: format!("{}[{}]", key.0, key.1),
        timestamps: &files[key].timestamps,
    };
    let sources = names
        .iter()
        .map(|(key, field)| (clock(key), files[key].fields[*field].clone()))
        .collect();
    let path = &files[&base_key].path;
    let first_us = files.values().map(|f| f.timestamps[0]).min().unwrap_or(0);
    Ok((
        join(path, &clock(&base_key), columns, sources)?,
        first_us as f64 * 1e-6,
    ))
}

/// The file of topic `topic`, instance `instance`: the one file of `dir` (whose files are
/// `listed`) named `<log>_<topic>_<instance>.csv`.
fn topic_file(dir: &Path, listed: &[PathBuf], topic: &str, instance: u8) -> Result<PathBuf> {
    let suffix = format!("_{topic}_{instance}.csv");
    let mut found: Vec<PathBuf> = listed
        .iter()
        .filter(|path| {
            path.file_name()
                .and_then(|n| n.to_str())
                .is_some_and(|n| n.ends_with(&suffix) && n.len() > suffix.len())
        })
        .cloned()
        .collect();
    found.sort();
    let config = |message: String| DataError::Config {
        path: dir.to_path_buf(),
        field: format!("{topic}[{instance}]"),
        message,
    };
    match found.len() {
        1 => Ok(found.remove(0)),
        0 => Err(config(format!(
            "no file named <log>{suffix} (a PX4 CSV export has one per topic instance)"
        ))),
        _ => Err(config(format!(
            "{} files end in {suffix}; export one log per folder",
            found.len()
        ))),
    }
}

/// The `timestamp` column and the fields `fields` of one topic's file. Cells may be NaN (PX4 logs
/// unused or not yet estimated values so); the analysis refuses them only on the rows it reads.
fn read_topic(path: &Path, fields: &[String]) -> Result<TopicFile> {
    let table = TextTable::read(path)?;
    let numbers = |name: &str| -> Result<Vec<f64>> {
        let cells = table.labels(name)?;
        cells
            .iter()
            .enumerate()
            .map(|(row, cell)| {
                cell.trim()
                    .parse::<f64>()
                    .map_err(|_| bad_cell(path, table.line(row), name, cell, "not a number".into()))
            })
            .collect()
    };
    let stamps = numbers("timestamp")?;
    let mut timestamps = Vec::with_capacity(stamps.len());
    for (row, &stamp) in stamps.iter().enumerate() {
        if !(stamp.is_finite() && stamp >= 0.0 && stamp.fract() == 0.0) {
            return Err(bad_cell(
                path,
                table.line(row),
                "timestamp",
                &stamp.to_string(),
                "a time stamp is a whole number of microseconds".into(),
            ));
        }
        let stamp = stamp as u64;
        // The as-of join reads each topic in time order.
        if timestamps.last().is_some_and(|&last| stamp < last) {
            return Err(bad_cell(
                path,
                table.line(row),
                "timestamp",
                &stamp.to_string(),
                "earlier than the row before: a topic's rows must be in time order".into(),
            ));
        }
        timestamps.push(stamp);
    }
    if timestamps.is_empty() {
        return Err(DataError::Config {
            path: path.to_path_buf(),
            field: "timestamp".into(),
            message: "the file has no samples".into(),
        });
    }
    let mut read = BTreeMap::new();
    for field in fields {
        if !read.contains_key(field) {
            read.insert(field.clone(), numbers(field)?);
        }
    }
    Ok(TopicFile {
        path: path.to_path_buf(),
        timestamps,
        fields: read,
    })
}
