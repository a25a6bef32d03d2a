//! `learn reproduce`: the paper's tables and figures from one command.

use std::path::PathBuf;

use anyhow::bail;
use pipeline::{OutputPaths, RunConfig, RunOptions, StageTiming};

use super::Global;

#[derive(clap::Args, Debug)]
pub struct Args {
    /// The run configuration (formulations, conditions, split, SINDy and LeARN settings, seeds).
    #[arg(long, default_value = "experiments/reproduce.json")]
    pub config: PathBuf,
    /// Where tables/, figures/, summary.json and timings.json are written.
    #[arg(long, default_value = "results")]
    pub out: PathBuf,
    /// Where the LaTeX tables are written.
    #[arg(long, default_value = "paper/tables")]
    pub latex_dir: PathBuf,
    /// Also rewrite the generated results block of this README.
    #[arg(long)]
    pub readme: Option<PathBuf>,
    /// The project root: relative paths in the run configuration start here.
    #[arg(long, default_value = ".")]
    pub root: PathBuf,
}

pub fn run(global: &Global, args: Args) -> anyhow::Result<()> {
    let start = std::time::Instant::now();
    let config = RunConfig::load(&args.config, &args.root)?;
    let paths = OutputPaths {
        results_dir: args.out,
        latex_dir: args.latex_dir,
        readme: args.readme,
    };
    // Before any directory is made: no output may be one of the inputs.
    let tables: Vec<&str> = config.raw.formulations.iter().map(|f| f.name()).collect();
    let planned = paths.planned(&tables);
    let inputs = config.input_files("--config");
    super::refuse_inputs_as_outputs(&planned, &inputs)?;
    if let Some(readme) = &paths.readme {
        // The README is updated in place; it must be no other input and no other output.
        let named: Vec<(&str, &std::path::Path)> = inputs
            .iter()
            .map(|(option, path)| (option.as_str(), path.as_path()))
            .collect();
        super::refuse_input_as_output(readme, &named)?;
        if let Some(output) = planned.clobbers(readme, &super::same_file) {
            bail!(
                "{}: the --readme to update is also an output of the run ({output})",
                readme.display()
            );
        }
    }
    let data_dir = global.data_dir()?;
    paths.check()?;
    let print_stage = |timing: &StageTiming| {
        eprintln!("{:>7.2} s  {}", timing.seconds, timing.stage);
    };
    let options = RunOptions {
        show_progress: global.show_progress(),
        on_stage: &print_stage,
    };
    eprintln!(
        "run '{}' on {} ({} threads)",
        config.raw.name,
        data_dir.display(),
        available_threads()
    );
    let outcome = pipeline::run(&config, &data_dir, &args.root, &options)?;
    let written = pipeline::write_outputs(&outcome, &paths)?;
    eprintln!(
        "{:>7.2} s  total; wrote {} files under {} and {}",
        start.elapsed().as_secs_f64(),
        written.len(),
        paths.results_dir.display(),
        paths.latex_dir.display()
    );
    for table in &outcome.tables {
        println!("\n{}", report::markdown(table));
    }
    Ok(())
}

fn available_threads() -> usize {
    std::thread::available_parallelism().map_or(1, |n| n.get())
}
