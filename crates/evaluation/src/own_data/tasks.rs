//! CSV tasks and recordings read for LeARN: the tasks of a [`TaskSource`] and a new recording,
//! with the columns of a [`ColumnSpec`] (`data` reads the files), handed to `learn` as in-memory
//! [`Recording`]s; a recording is checked against the sampling interval of a model's tasks.

use std::ops::Range;
use std::path::Path;

use data::{DEFAULT_UNIFORM_TOLERANCE, TaskTable, interval_text};
use learn::{
    ColumnSpec, ColumnTraining, DataFile, LearnError, MetaTrainedModel, Recording,
    RecordingEvaluation, TaskSource,
};

use crate::error::Result;

/// Reads the tasks of `source` with the columns of `spec` (in its order: states, then controls).
pub fn read_tasks(source: &TaskSource, spec: &ColumnSpec) -> Result<Vec<TaskTable>> {
    let names = spec.input_names();
    let columns: Vec<&str> = names.iter().map(String::as_str).collect();
    Ok(match source {
        TaskSource::Files { pattern } => data::read_file_tasks(pattern, &spec.time, &columns)?,
        TaskSource::Column { file, column } => {
            data::read_column_tasks(file, column, &spec.time, &columns)?
        }
    })
}

/// The files `tasks` were read from, each once and in their order, with their SHA-256 (what a
/// model records of its data).
pub fn data_files(tasks: &[TaskTable]) -> Result<Vec<DataFile>> {
    let mut files: Vec<DataFile> = Vec::new();
    for task in tasks {
        if !files.iter().any(|file| file.path == task.path) {
            files.push(DataFile {
                path: task.path.clone(),
                sha256: data::file_sha256(&task.path)?,
            });
        }
    }
    Ok(files)
}

/// Reads one recording with the columns of `spec`.
pub fn read_recording(path: &Path, spec: &ColumnSpec) -> Result<TaskTable> {
    let names = spec.input_names();
    let columns: Vec<&str> = names.iter().map(String::as_str).collect();
    Ok(TaskTable::read(path, &spec.time, &columns)?)
}

/// A task or recording as LeARN reads it: its columns in memory.
pub fn recording(table: &TaskTable) -> Recording<'_> {
    Recording {
        name: &table.name,
        path: &table.path,
        columns: &table.table.columns,
        interval: table.interval,
    }
}

/// The recording is sampled at the interval of the model's tasks (within the tolerance of a
/// uniform time axis); otherwise an error naming its file and both intervals.
pub fn check_interval(columns: &ColumnTraining, recording: &TaskTable) -> Result<()> {
    let reference = columns.sampling_interval;
    if (recording.interval - reference).abs() > DEFAULT_UNIFORM_TOLERANCE * reference {
        return Err(LearnError::Task {
            path: recording.path.clone(),
            message: format!(
                "column '{}' is sampled every {} s, the model's tasks every {} s: resample the recording",
                columns.time,
                interval_text(recording.interval),
                interval_text(reference)
            ),
        }
        .into());
    }
    Ok(())
}

/// [`learn::evaluate_recording`] on `recording`, after checking it is sampled at the interval of
/// the model's tasks ([`check_interval`]).
pub(crate) fn evaluate_on(
    model: &MetaTrainedModel,
    recording: &TaskTable,
    support: Range<usize>,
    query: Range<usize>,
) -> Result<RecordingEvaluation> {
    check_interval(learn::column_training(model, "evaluation")?, recording)?;
    Ok(learn::evaluate_recording(
        model,
        self::recording(recording),
        support,
        query,
    )?)
}

#[cfg(test)]
mod tests {
    use super::*;
    use sindy::Derivative;

    fn spec() -> ColumnSpec {
        ColumnSpec {
            time: "t".to_string(),
            state: vec!["x".to_string()],
            control: vec!["u".to_string()],
            derivative: Derivative::Forward,
        }
    }

    #[test]
    fn tasks_are_read_by_pattern_or_column_and_recordings_checked_against_the_interval() {
        let dir = tempfile::Builder::new()
            .prefix("evaluation-tasks-")
            .tempdir()
            .unwrap();
        let write = |name: &str, text: &str| {
            let path = dir.path().join(name);
            std::fs::write(&path, text).unwrap();
            path
        };
        write("a.csv", "t,u,x\n0,1,10\n0.1,2,20\n0.2,3,30\n");
        write("b.csv", "t,u,x\n0,4,40\n0.1,5,50\n0.2,6,60\n");
        let pattern = format!("{}/*.csv", dir.path().display());
        let tasks = read_tasks(&TaskSource::Files { pattern }, &spec()).unwrap();
        let views: Vec<Recording> = tasks.iter().map(recording).collect();
        assert_eq!(views[1].name, "b.csv");
        // States, then controls, whatever the order of the file's columns.
        assert_eq!(
            views[1].columns,
            [vec![40.0, 50.0, 60.0], vec![4.0, 5.0, 6.0]]
        );
        assert_eq!(views[1].rows(), 3);
        let all = write(
            "all.csv",
            "task,t,x,u\na,0,1,0\na,0.1,2,0\nb,0,3,0\nb,0.1,4,0\n",
        );
        let source = TaskSource::Column {
            file: all,
            column: "task".to_string(),
        };
        let runs = read_tasks(&source, &spec()).unwrap();
        assert_eq!(recording(&runs[1]).name, "all.csv[task=b]");

        let slow = read_recording(
            &write("slow.csv", "t,x,u\n0,1,0\n0.5,2,0\n1,3,0\n"),
            &spec(),
        )
        .unwrap();
        let columns = ColumnTraining {
            time: "t".to_string(),
            state: vec!["x".to_string()],
            control: vec!["u".to_string()],
            derivative: Derivative::Forward,
            sampling_interval: tasks[0].interval,
            target_scale: vec![1.0],
            source: TaskSource::Files {
                pattern: "*.csv".to_string(),
            },
            tasks: Vec::new(),
        };
        assert!(check_interval(&columns, &tasks[1]).is_ok());
        let message = check_interval(&columns, &slow).unwrap_err().to_string();
        assert!(
            message.contains("slow.csv") && message.contains("sampled every 0.5 s"),
            "{message}"
        );
    }
}
