//! `learn ablations`: every variant of `experiments/variants.json` on every cell, over its seeds.

use std::path::PathBuf;

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
    /// Only rewrite `<out>/ablations.md` from an existing `ablations.json` (no fitting; --config
    /// and --root do not apply).
    #[arg(long)]
    pub render_only: bool,
}

pub fn run(global: &Global, args: Args) -> anyhow::Result<()> {
    let start = std::time::Instant::now();
    if args.render_only {
        let json = args.out.join("ablations.json");
        let text = std::fs::read_to_string(&json)
            .map_err(|e| anyhow::anyhow!("{}: {e}", json.display()))?;
        let ablations: pipeline::Ablations =
            data::json::from_str(&text).map_err(|e| anyhow::anyhow!("{}: {e}", json.display()))?;
        let markdown = pipeline::ablations_markdown(&ablations);
        let md = args.out.join("ablations.md");
        std::fs::write(&md, &markdown).map_err(|e| anyhow::anyhow!("{}: {e}", md.display()))?;
        println!("{markdown}");
        return Ok(());
    }
    let config = VariantsConfig::load(&args.config, &args.root)?;
    // Before any directory is made: no output may be one of the inputs.
    super::refuse_inputs_as_outputs(
        &pipeline::planned_ablations(&args.out),
        &config.input_files("--config"),
    )?;
    let data_dir = global.data_dir()?;
    pipeline::check_ablations_output(&args.out)?;
    // Per-cell lines only on a terminal and without --quiet (a log gets the final summary).
    let show_progress = global.show_progress();
    let progress = |cell: &str| {
        if show_progress {
            eprintln!("{:>7.1} s  {cell}", start.elapsed().as_secs_f64());
        }
    };
    let outcome = pipeline::run_variants(&config, &data_dir, &progress)?;
    let written = pipeline::write_ablations(&outcome, &args.out)?;
    eprintln!(
        "{:>7.1} s  total; wrote {} files under {}",
        start.elapsed().as_secs_f64(),
        written.len(),
        args.out.display()
    );
    println!("{}", pipeline::ablations_markdown(&outcome.ablations));
    Ok(())
}
