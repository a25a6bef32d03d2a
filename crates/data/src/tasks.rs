//! Several recordings of one system, each a task of meta-learning (a robot arm with different
//! payloads, a vehicle on different surfaces): every CSV file matched by a glob pattern
//! ([`read_file_tasks`]), or the runs of one CSV that share a value of a task column
//! ([`read_column_tasks`]). Each task is read as `learn sindy` reads its file ([`NumericTable`]:
//! columns by name, `v[k]` for an element of a list column, a strictly increasing, uniformly
//! sampled time column), and all tasks must share one sampling interval.

use std::path::{Path, PathBuf};

use bounded_read::Excerpt;

use crate::error::{DataError, Result};
use crate::numeric::NumericTable;
use crate::table::TextTable;
use crate::time::{DEFAULT_UNIFORM_TOLERANCE, check_time_axis_at, median_interval};

/// The most tasks read at once.
pub const MAX_TASKS: usize = 10_000;

/// One task: its rows of the time column and of the named columns.
#[derive(Clone, Debug)]
pub struct TaskTable {
    /// The file name, or `file[column=value]` for a task of a task column.
    pub name: String,
    /// The file the task was read from.
    pub path: PathBuf,
    pub time: Vec<f64>,
    /// The named columns, in the order given.
    pub table: NumericTable,
    /// The median sampling interval, seconds.
    pub interval: f64,
}

impl TaskTable {
    /// Reads one recording as a task: the column `time` and `columns` of the CSV at `path`.
    pub fn read(path: &Path, time: &str, columns: &[&str]) -> Result<Self> {
        read_file_task(path, time, columns)
    }

    /// Number of rows.
    pub fn rows(&self) -> usize {
        self.time.len()
    }
}

/// Reads one task per regular file matched by the glob `pattern` (`*`, `?`, `[…]`, `**`), in
/// sorted path order: the column `time` and `columns` of each. Errors name the file, row and
/// column: a pattern that matches no file, a task without a named column, a time axis that is not
/// uniform, tasks sampled at different intervals.
pub fn read_file_tasks(pattern: &str, time: &str, columns: &[&str]) -> Result<Vec<TaskTable>> {
    let tasks = matched_files(pattern)?
        .iter()
        .map(|path| read_file_task(path, time, columns))
        .collect::<Result<Vec<_>>>()?;
    check_common_interval(&tasks, time)?;
    Ok(tasks)
}

/// Reads one task per run of consecutive rows of the CSV at `path` with the same value of the
/// column `column`: the column `time` and `columns` of each. Errors name the file, row and
/// column: as [`read_file_tasks`], and a task column whose values return after another's.
pub fn read_column_tasks(
    path: &Path,
    column: &str,
    time: &str,
    columns: &[&str],
) -> Result<Vec<TaskTable>> {
    let tasks = read_task_runs(path, column, time, columns)?;
    check_common_interval(&tasks, time)?;
    Ok(tasks)
}

/// The regular files matched by `pattern`, sorted; an error when there is none.
fn matched_files(pattern: &str) -> Result<Vec<PathBuf>> {
    let invalid = |message: String| DataError::Invalid {
        what: format!("--tasks '{pattern}'"),
        message,
    };
    let paths = glob::glob(pattern).map_err(|error| invalid(error.to_string()))?;
    let mut files = Vec::new();
    for entry in paths {
        let path = entry.map_err(|error| DataError::Io {
            path: error.path().to_path_buf(),
            source: std::io::Error::new(error.error().kind(), error.error().to_string()),
        })?;
        if path.is_file() {
            files.push(path);
        }
        if files.len() > MAX_TASKS {
            return Err(invalid(format!(
                "matches more than {MAX_TASKS} files, the most tasks read at once"
            )));
        }
    }
    if files.is_empty() {
        return Err(invalid(
            "matches no file (quote the pattern so that the shell does not expand it)".to_string(),
        ));
    }
    files.sort();
    Ok(files)
}

fn read_file_task(path: &Path, time: &str, columns: &[&str]) -> Result<TaskTable> {
    let (time_values, table) = NumericTable::read_with_time(path, time, columns)?;
    Ok(TaskTable {
        name: path.file_name().map_or_else(
            || path.display().to_string(),
            |n| n.to_string_lossy().into(),
        ),
        path: path.to_path_buf(),
        interval: median_interval(&time_values),
        time: time_values,
        table,
    })
}

/// The tasks of one file split by the value of `column`: each a run of consecutive rows.
fn read_task_runs(
    path: &Path,
    column: &str,
    time: &str,
    columns: &[&str],
) -> Result<Vec<TaskTable>> {
    let text = TextTable::read(path)?;
    let labels = text.labels(column)?;
    let mut names = vec![time];
    names.extend_from_slice(columns);
    let whole = NumericTable::from_text(&text, &names)?;
    let mut runs: Vec<(String, std::ops::Range<usize>)> = Vec::new();
    for (row, label) in labels.iter().enumerate() {
        match runs.last_mut() {
            Some((last, rows)) if last == label => rows.end = row + 1,
            _ => {
                if runs.iter().any(|(seen, _)| seen == label) {
                    let previous = runs.last().map_or("", |(name, _)| name.as_str());
                    return Err(crate::cells::bad_cell(
                        path,
                        text.line(row),
                        column,
                        label,
                        format!(
                            "task '{}' appears again after task '{}': a task's rows must be consecutive",
                            Excerpt::of(label).unquoted(),
                            Excerpt::of(previous).unquoted()
                        ),
                    ));
                }
                if runs.len() == MAX_TASKS {
                    return Err(DataError::Invalid {
                        what: format!("{}: column '{column}'", path.display()),
                        message: format!("more than {MAX_TASKS} tasks, the most read at once"),
                    });
                }
                runs.push((label.clone(), row..row + 1));
            }
        }
    }
    runs.into_iter()
        .map(|(label, rows)| {
            let mut table = whole.rows_subset(rows);
            let time_values = table.columns.remove(0);
            table.names.remove(0);
            check_time_axis_at(path, time, &time_values, DEFAULT_UNIFORM_TOLERANCE, &|k| {
                table.line(k)
            })?;
            Ok(TaskTable {
                name: format!(
                    "{}[{column}={label}]",
                    path.file_name().map_or_else(
                        || path.display().to_string(),
                        |n| n.to_string_lossy().into()
                    )
                ),
                path: path.to_path_buf(),
                interval: median_interval(&time_values),
                time: time_values,
                table,
            })
        })
        .collect()
}

/// A sampling interval in seconds as a person writes it: 0.1, not the median gap
/// 0.09999999999999987 the time column's rounding gives.
pub fn interval_text(seconds: f64) -> String {
    let text = format!("{seconds:.9}");
    let text = text.trim_end_matches('0').trim_end_matches('.');
    if text == "0" || text == "-0" {
        format!("{seconds:e}")
    } else {
        text.to_string()
    }
}

/// Every task sampled at the first task's interval, within the uniform-sampling tolerance.
fn check_common_interval(tasks: &[TaskTable], time: &str) -> Result<()> {
    let Some(first) = tasks.first() else {
        return Ok(());
    };
    let reference = first.interval;
    match tasks
        .iter()
        .find(|task| (task.interval - reference).abs() > DEFAULT_UNIFORM_TOLERANCE * reference)
    {
        Some(task) => Err(DataError::Task {
            path: task.path.clone(),
            message: format!(
                "{time}: task '{}' is sampled every {} s, task '{}' every {} s: all tasks must share one sampling interval",
                task.name,
                interval_text(task.interval),
                first.name,
                interval_text(reference)
            ),
        }),
        None => Ok(()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn write(dir: &Path, name: &str, text: &str) -> PathBuf {
        std::fs::create_dir_all(dir).unwrap();
        let path = dir.join(name);
        std::fs::write(&path, text).unwrap();
        path
    }

    /// A temporary folder, removed when dropped.
    fn scratch(name: &str) -> tempfile::TempDir {
        tempfile::Builder::new()
            .prefix(&format!("data-tasks-{name}-"))
            .tempdir()
            .unwrap()
    }

    #[test]
    fn a_glob_reads_one_task_per_file_in_sorted_order_with_list_elements() {
        let scratch_dir = scratch("glob");
        let dir = scratch_dir.path().to_path_buf();
        write(
            &dir,
            "b.csv",
            "t,v,u\n0,\"[1, 2]\",5\n0.1,\"[3, 4]\",6\n0.2,\"[5, 6]\",7\n",
        );
        write(&dir, "a.csv", "t,v,u\n0,\"[0, 1]\",1\n0.1,\"[0, 2]\",1\n");
        write(&dir, "notes.txt", "not a task");
        let pattern = format!("{}/*.csv", dir.display());
        let tasks = read_file_tasks(&pattern, "t", &["v[1]", "u"]).unwrap();
        let names: Vec<&str> = tasks.iter().map(|t| t.name.as_str()).collect();
        assert_eq!(names, ["a.csv", "b.csv"]);
        assert_eq!(
            tasks[1].table.columns,
            vec![vec![2.0, 4.0, 6.0], vec![5.0, 6.0, 7.0]]
        );
        assert!((tasks[1].interval - 0.1).abs() < 1e-12);
    }

    #[test]
    fn a_pattern_that_matches_nothing_or_tasks_sampled_differently_are_named() {
        let scratch_dir = scratch("bad");
        let dir = scratch_dir.path().to_path_buf();
        let pattern = format!("{}/*.csv", dir.display());
        let message = read_file_tasks(&pattern, "t", &["x"])
            .unwrap_err()
            .to_string();
        assert!(message.contains("matches no file"), "{message}");
        write(&dir, "a.csv", "t,x\n0,1\n0.1,2\n0.2,3\n");
        write(&dir, "b.csv", "t,x\n0,1\n0.2,2\n0.4,3\n");
        let message = read_file_tasks(&pattern, "t", &["x"])
            .unwrap_err()
            .to_string();
        assert!(
            message.contains("b.csv") && message.contains("a.csv"),
            "{message}"
        );
        write(&dir, "b.csv", "t,y\n0,1\n0.1,2\n");
        let message = read_file_tasks(&pattern, "t", &["x"])
            .unwrap_err()
            .to_string();
        assert!(message.contains("b.csv: missing column 'x'"), "{message}");
    }

    #[test]
    fn a_task_column_splits_one_file_into_runs_and_refuses_a_returning_task() {
        let scratch_dir = scratch("column");
        let dir = scratch_dir.path().to_path_buf();
        let file = write(
            &dir,
            "all.csv",
            "task,t,x\nslow,0,1\nslow,0.1,2\nfast,5,3\nfast,5.1,4\nfast,5.2,5\n",
        );
        let tasks = read_column_tasks(&file, "task", "t", &["x"]).unwrap();
        assert_eq!(tasks.len(), 2);
        assert_eq!(tasks[1].name, "all.csv[task=fast]");
        assert_eq!(tasks[1].table.columns[0], vec![3.0, 4.0, 5.0]);
        assert_eq!(tasks[1].table.line(0), 4);
        write(
            &dir,
            "all.csv",
            "task,t,x\na,0,1\na,0.1,2\nb,0,3\nb,0.1,3\na,0.2,4\n",
        );
        let message = read_column_tasks(&file, "task", "t", &["x"])
            .unwrap_err()
            .to_string();
        assert!(message.contains("all.csv:6:task"), "{message}");
        assert!(message.contains("consecutive"), "{message}");
    }
}
