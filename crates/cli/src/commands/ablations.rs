//! `learn ablations`: every variant of `experiments/variants.json` on every cell, over its seeds.

use std::path::PathBuf;

use outputs::{Existing, OutputSet};
use pipeline::VariantsConfig;

use super::Global;

#[derive(clap::Args, Debug)]
pub struct Args {
    /// The variants configuration (variants, seeds, headline, figure variant).
    #[arg(
        long,
        default_value = "experiments/variants.json",
        conflicts_with = "render_only"
    )]
    pub config: PathBuf,
    /// Where ablations.{json,md} and figures/ are written.
    #[arg(long, default_value = "results/ablations")]
    pub out: PathBuf,
    /// The project root: relative paths in the configuration start here.
    #[arg(long, default_value = ".", conflicts_with = "render_only")]
    pub root: PathBuf,
    /// Replace the files an earlier `learn ablations` wrote in --out (files it did not write are
    /// never replaced).
    #[arg(long)]
    pub force: bool,
    /// Only rewrite `<out>/ablations.md` from an existing `ablations.json` (no fitting; --config
    /// and --root do not apply).
    #[arg(long)]
    pub render_only: bool,
}

/// What the output manifest records as the writer of these files.
const PRODUCER: &str = "ablations";

pub fn run(global: &Global, args: Args) -> anyhow::Result<()> {
    if args.render_only {
        return render_only(&args);
    }
    let start = std::time::Instant::now();
    let config = VariantsConfig::load(&args.config, &args.root)?;
    let mut set = OutputSet::new(PRODUCER);
    for (what, path) in config.input_files("--config") {
        set.input(format!("the {what} input"), path);
    }
    let folder = set.folder(&args.out, "--out", Existing::from_force(args.force));
    for file in pipeline::ablation_files() {
        set.file_in(folder, file);
    }
    // The figures' names depend on the cells: checked when the set is committed.
    set.subfolder_in(folder, "figures");
    set.check()?;
    let data_dir = global.data_dir()?;
    let staged = set.prepare()?;
    // Per-cell lines only on a terminal and without --quiet (a log gets the final summary).
    let show_progress = global.show_progress();
    let progress = |cell: &str| {
        if show_progress {
            note!("{:>7.1} s  {cell}", start.elapsed().as_secs_f64());
        }
    };
    let outcome = pipeline::run_variants(&config, &data_dir, &progress)?;
    super::staged_write(&staged, || {
        pipeline::write_ablations(&outcome, staged.dir(folder))
    })?;
    let written = staged.commit()?;
    note!(
        "{:>7.1} s  total; wrote {} files under {}",
        start.elapsed().as_secs_f64(),
        written.len(),
        args.out.display()
    );
    say!("{}", pipeline::ablations_markdown(&outcome.ablations));
    Ok(())
}

/// `--render-only`: `ablations.md` again from the `ablations.json` of an earlier run.
fn render_only(args: &Args) -> anyhow::Result<()> {
    let json = args.out.join("ablations.json");
    let text =
        inputs::read_json_text(&json).map_err(|e| anyhow::anyhow!("{}: {e}", json.display()))?;
    let ablations: pipeline::Ablations =
        inputs::json::from_str(&text).map_err(|e| anyhow::anyhow!("{}: {e}", json.display()))?;
    let markdown = pipeline::ablations_markdown(&ablations);
    // Only ablations.md is rewritten: the run's other files stay its own.
    let mut set = OutputSet::new(PRODUCER).updating_only_its_files();
    set.input("the ablations.json input", &json);
    let folder = set.folder(&args.out, "--out", Existing::from_force(args.force));
    set.file_in(folder, "ablations.md");
    let staged = set.prepare()?;
    let md = staged.dir(folder).join("ablations.md");
    std::fs::write(&md, &markdown).map_err(|e| anyhow::anyhow!("{}: {e}", md.display()))?;
    staged.commit()?;
    say!("{markdown}");
    Ok(())
}
