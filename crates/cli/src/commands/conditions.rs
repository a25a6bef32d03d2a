//! `learn conditions`.

use std::path::PathBuf;

use data::ExperimentConditions;

use super::Global;

#[derive(clap::Args, Debug)]
pub struct Args {
    /// The conditions file.
    #[arg(long, default_value = "experiments/conditions.json")]
    pub config: PathBuf,
}

pub fn run(global: &Global, args: Args) -> anyhow::Result<()> {
    let config = ExperimentConditions::load(&args.config)?;
    let data_dir = global.optional_data_dir()?;
    say!(
        "{:<12} {:<10} {:<24} {:<14} files present",
        "condition",
        "label",
        "wind speed",
        "role"
    );
    for condition in &config.conditions {
        let present = match &data_dir {
            Some(dir) => {
                let files: Vec<_> = config
                    .flight_files(dir)
                    .into_iter()
                    .filter(|f| f.condition == condition.name && f.controller != "paper-training")
                    .collect();
                let names: Vec<String> = files
                    .iter()
                    .map(|f| {
                        format!(
                            "{}{}",
                            f.controller,
                            if f.present { "" } else { " (missing)" }
                        )
                    })
                    .collect();
                format!(
                    "{}/{}: {}",
                    files.iter().filter(|f| f.present).count(),
                    files.len(),
                    names.join(", ")
                )
            }
            None => "no data directory (run `make data`)".to_string(),
        };
        let role = match condition.role {
            data::Role::Evaluation => "evaluation",
            data::Role::MetaTraining => "meta-training",
        };
        say!(
            "{:<12} {:<10} {:<24} {:<14} {present}",
            condition.name,
            condition.label(),
            condition.wind_speed,
            role
        );
    }
    if let Some(dir) = &data_dir {
        let paper = config.paper_training_present(dir);
        say!(
            "paper meta-training flights ({}): {}",
            config.paper_training.file_pattern,
            if paper {
                "present (protocol `paper` available)"
            } else {
                "absent (protocol `leave-condition-out` is used)"
            }
        );
        say!("data directory: {}", dir.display());
    }
    Ok(())
}
