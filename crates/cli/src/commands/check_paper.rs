//! `learn check-paper`: the latest results beside the published numbers, within declared tolerances.

use std::path::PathBuf;

use super::Global;

#[derive(clap::Args, Debug)]
pub struct Args {
    /// Directory of the results tables (`<table>.json`) to check.
    #[arg(long, default_value = "results/tables")]
    pub results: PathBuf,
    /// The paper's numbers.
    #[arg(long, default_value = "paper/published.json")]
    pub published: PathBuf,
    /// Per-cell tolerances and the evidence behind them.
    #[arg(long, default_value = "paper/tolerances.json")]
    pub tolerances: PathBuf,
}

pub fn run(_global: &Global, args: Args) -> anyhow::Result<()> {
    let comparison = evaluation::check_paper(&args.results, &args.published, &args.tolerances)?;
    say_part!("{}", comparison.render_text());
    let failed = comparison.failures().count();
    if failed > 0 {
        anyhow::bail!(
            "{failed} published cell(s) outside tolerance (results in {}, tolerances in {})",
            args.results.display(),
            args.tolerances.display()
        );
    }
    Ok(())
}
