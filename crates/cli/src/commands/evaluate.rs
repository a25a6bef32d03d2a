//! `learn evaluate --model MODEL.json --csv FILE --support-rows A:B --query-rows C:D [--json]`:
//! a model of `learn meta-train --tasks` adapted online on the support rows of a new recording and
//! scored on its query rows, next to SINDy fitted on the same support rows.

use std::ops::Range;
use std::path::PathBuf;

use anyhow::{Context, bail};
use evaluation::own_data::{RecordingComparison, SindySettings, compare_on_recording};
use learn::MetaTrainedModel;

use super::Global;
use super::sindy::FitArgs;

#[derive(clap::Args, Debug)]
pub struct Args {
    /// A model written by `learn meta-train --tasks`.
    #[arg(long)]
    pub model: PathBuf,
    /// The new recording: a CSV with the model's time, state and control columns.
    #[arg(long)]
    pub csv: PathBuf,
    /// Rows the model adapts on (and SINDy is fitted on): A:B, data rows from 0, B excluded.
    #[arg(long, value_parser = parse_rows)]
    pub support_rows: Range<usize>,
    /// Rows both are scored on without any further update: C:D, as --support-rows.
    #[arg(long, value_parser = parse_rows)]
    pub query_rows: Range<usize>,
    /// Print `{"learn": {"adapt", "gen"}, "sindy": {"adapt", "gen"}}` instead of a table.
    #[arg(long)]
    pub json: bool,
    /// The SINDy baseline (the library and optimizer options of `learn sindy`; its derivative is
    /// the model's).
    #[command(flatten)]
    pub sindy: FitArgs,
}

/// `A:B` with A < B, whole numbers.
pub(crate) fn parse_rows(text: &str) -> Result<Range<usize>, String> {
    let bad = || {
        format!("rows are A:B, data rows counted from 0 with B excluded and A < B (got {text:?})")
    };
    let (start, end) = text.split_once(':').ok_or_else(bad)?;
    let start: usize = start.trim().parse().map_err(|_| bad())?;
    let end: usize = end.trim().parse().map_err(|_| bad())?;
    if start >= end {
        return Err(bad());
    }
    Ok(start..end)
}

fn overlap(a: &Range<usize>, b: &Range<usize>) -> bool {
    a.start < b.end && b.start < a.end
}

pub fn run(_global: &Global, args: Args) -> anyhow::Result<()> {
    let settings = SindySettings {
        library: args.sindy.library()?,
        optimizer: args.sindy.optimizer()?,
    };
    if overlap(&args.support_rows, &args.query_rows) {
        bail!(
            "--support-rows {}:{} and --query-rows {}:{} overlap: the query must be rows the model was not adapted on",
            args.support_rows.start,
            args.support_rows.end,
            args.query_rows.start,
            args.query_rows.end
        );
    }
    let model = MetaTrainedModel::load(&args.model)?;
    let columns = learn::column_training(&model, &args.model.display().to_string())?;
    let recording = evaluation::own_data::read_recording(&args.csv, &columns.spec())?;
    let comparison = compare_on_recording(
        &model,
        &recording,
        args.support_rows.clone(),
        args.query_rows.clone(),
        &settings,
    )?;
    if args.json {
        let value = serde_json::json!({
            "learn": comparison.learn,
            "sindy": comparison.sindy,
        });
        say!("{}", serde_json::to_string(&value).context("JSON")?);
        return Ok(());
    }
    print_table(&args, &comparison);
    Ok(())
}

fn print_table(args: &Args, comparison: &RecordingComparison) {
    let evaluation = &comparison.evaluation;
    say!(
        "{}: adapted on rows {}:{} ({} samples), scored on rows {}:{} ({} samples)",
        args.csv.display(),
        evaluation.support_rows.start,
        evaluation.support_rows.end,
        evaluation.support_rows.len(),
        evaluation.query_rows.start,
        evaluation.query_rows.end,
        evaluation.query_rows.len()
    );
    say!("{:<22} {:>14} {:>14}", "method", "adapt MSE", "gen MSE");
    for (name, scores) in [
        ("LeARN (adapted)", comparison.learn),
        ("LeARN (not adapted)", comparison.learn_unadapted),
        ("SINDy", comparison.sindy),
    ] {
        say!(
            "{name:<22} {:>14.6} {:>14.6}",
            scores.adaptation,
            scores.generalisation
        );
    }
    let (learn, sindy) = (
        comparison.learn.generalisation,
        comparison.sindy.generalisation,
    );
    let verdict = if learn < sindy {
        format!(
            "LeARN generalises better here ({:.1}% lower MSE)",
            100.0 * (1.0 - learn / sindy)
        )
    } else {
        format!(
            "SINDy generalises as well or better here ({:.1}% lower MSE)",
            100.0 * (1.0 - sindy / learn)
        )
    };
    say!("{verdict}");
    say!("SINDy fitted on the support rows:");
    for line in comparison.sindy_model.equations(3) {
        say!("    {line}");
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rows_are_a_half_open_range() {
        assert_eq!(parse_rows("0:100"), Ok(0..100));
        for bad in ["5:5", "7:3", "a:3", "3", "-1:4"] {
            assert!(parse_rows(bad).is_err(), "{bad}");
        }
        assert!(overlap(&(0..10), &(9..20)) && !overlap(&(0..10), &(10..20)));
    }
}
