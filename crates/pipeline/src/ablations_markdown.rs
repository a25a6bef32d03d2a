//! The ablation tables as Markdown (`results/ablations/ablations.md`), from `ablations.json`
//! alone: `learn ablations`, `learn ablations --render-only` and `learn merge` all write it here.

use crate::ablations::Ablations;

/// The ablation tables as Markdown: the headline comparison, then every variant's generalisation
/// and adaptation MSE (mean ± standard deviation over seeds) per formulation.
pub fn ablations_markdown(ablations: &Ablations) -> String {
    let config = &ablations.config;
    let seeds = config
        .seeds
        .iter()
        .map(u64::to_string)
        .collect::<Vec<_>>()
        .join(", ");
    let mut out = format!(
        "# Ablations: {}\n\n{}\n\nProtocol: {}. Seeds: {seeds}. MSE = mean over samples and state \
         dimensions; `±` is the standard deviation over seeds (0 for deterministic variants).\n\n\
         Noise floor of the forward-difference target on the query segment (`data::forward_difference_noise_floor`): \
         `lower–upper`, where upper = mean square of forward difference minus a Savitzky–Golay(21, 3) \
         derivative (counts motion faster than 0.4 s as noise) and lower = twice the negative lag-one \
         autocovariance of that residual.\n\n",
        ablations.name, ablations.description, ablations.protocol
    );
    out.push_str(&format!(
        "## Headline: `{}` against min(published SINDy gen, published LeARN gen)\n\n",
        config.headline
    ));
    out.push_str("| table | condition | published SINDy gen | published LeARN gen | target | ours SINDy gen | headline gen | vs target | below target | noise floor (query) | headline / floor upper |\n");
    out.push_str("|---|---|---|---|---|---|---|---|---|---|---|\n");
    let mut wins = 0;
    for row in &ablations.rows {
        let headline = &row.variants[&config.headline];
        let (pub_sindy, pub_learn) = row
            .published
            .map(|p| {
                (
                    format!("{:.3}", p.sindy.generalisation),
                    format!("{:.3}", p.learn.generalisation),
                )
            })
            .unwrap_or(("–".to_string(), "–".to_string()));
        let (target, versus, below) = match row.target {
            Some(target) => {
                let below = headline.r#gen < target;
                wins += usize::from(below);
                (
                    format!("{target:.3}"),
                    format!("{:+.1} %", 100.0 * (headline.r#gen / target - 1.0)),
                    if below { "yes" } else { "**no**" }.to_string(),
                )
            }
            None => ("–".to_string(), "–".to_string(), "–".to_string()),
        };
        out.push_str(&format!(
            "| {} | {} | {pub_sindy} | {pub_learn} | {target} | {:.3} | {:.3} ± {:.3} | {versus} | {below} | {:.3}–{:.3} | {:.2} |\n",
            row.table,
            row.condition,
            row.sindy.generalisation,
            headline.r#gen,
            headline.gen_std,
            row.noise_floor_query.lower,
            row.noise_floor_query.upper,
            headline.r#gen / row.noise_floor_query.upper,
        ));
    }
    out.push_str(&format!(
        "\n`{}` is below the target in {wins} of {} cells.\n\n",
        config.headline,
        ablations.rows.iter().filter(|r| r.target.is_some()).count()
    ));
    out.push_str(
        "## Distance above the noise floor: generalisation MSE ÷ the query floor's upper estimate\n\n\
         1.00 would mean nothing but (upper-estimate) noise is left; the lower estimate shows how \
         much of that upper estimate may itself be fast, predictable motion.\n\n\
         | table | condition | floor (lower–upper) | published SINDy | published LeARN | ours SINDy | headline | best variant |\n\
         |---|---|---|---|---|---|---|---|\n",
    );
    for row in &ablations.rows {
        let floor = row.noise_floor_query.upper;
        let ratio = |value: f64| format!("{:.2}", value / floor);
        let (pub_sindy, pub_learn) = row
            .published
            .map(|p| (ratio(p.sindy.generalisation), ratio(p.learn.generalisation)))
            .unwrap_or(("–".to_string(), "–".to_string()));
        let best = row
            .variants
            .values()
            .map(|v| v.r#gen)
            .fold(f64::INFINITY, f64::min);
        out.push_str(&format!(
            "| {} | {} | {:.3}–{floor:.3} | {pub_sindy} | {pub_learn} | {} | {} | {} |\n",
            row.table,
            row.condition,
            row.noise_floor_query.lower,
            ratio(row.sindy.generalisation),
            ratio(row.variants[&config.headline].r#gen),
            ratio(best),
        ));
    }
    out.push('\n');
    if let Some(name) = &config.figure_variant {
        out.push_str(&format!(
            "## Predictive band of `{name}` (drawn in `figures/`): share of query targets inside it\n\n\
             Band = ensemble mean ± 2·√(members' variance + the output's support CV MSE); about 0.95 \
             is expected if the errors were Gaussian and the query behaved like the support.\n\n\
             | table | condition | coverage (mean over seeds) |\n|---|---|---|\n"
        ));
        for row in &ablations.rows {
            let values: Vec<f64> = row.variants[name]
                .seeds
                .iter()
                .filter_map(|s| s.query_band_coverage)
                .collect();
            if !values.is_empty() {
                let mean = values.iter().sum::<f64>() / values.len() as f64;
                out.push_str(&format!(
                    "| {} | {} | {mean:.3} |\n",
                    row.table, row.condition
                ));
            }
        }
        out.push('\n');
    }
    out.push_str("## Best variant per cell (generalisation MSE, mean over seeds)\n\n");
    out.push_str("| table | condition | best variant | gen | target | vs target |\n|---|---|---|---|---|---|\n");
    for row in &ablations.rows {
        let (name, cell) = row
            .variants
            .iter()
            .min_by(|a, b| a.1.r#gen.total_cmp(&b.1.r#gen))
            .expect("at least one variant");
        let versus = row
            .target
            .map(|t| format!("{:+.1} %", 100.0 * (cell.r#gen / t - 1.0)))
            .unwrap_or_else(|| "–".to_string());
        let target = row
            .target
            .map(|t| format!("{t:.3}"))
            .unwrap_or_else(|| "–".to_string());
        out.push_str(&format!(
            "| {} | {} | `{name}` | {:.3} | {target} | {versus} |\n",
            row.table, row.condition, cell.r#gen
        ));
    }
    out.push_str("\n(Picking the best variant per cell by its query error is itself a choice made on the query segment: this table is descriptive. The headline column above is declared in `experiments/variants.json`; its description says when it was chosen.)\n\n");
    for metric in ["gen", "adapt"] {
        out.push_str(&format!(
            "## Every variant, {metric} MSE (mean ± std over seeds)\n\n"
        ));
        let names: Vec<&str> = config.variants.iter().map(|v| v.name.as_str()).collect();
        out.push_str("| table | condition | ours SINDy |");
        for name in &names {
            out.push_str(&format!(" `{name}` |"));
        }
        out.push_str("\n|---|---|---|");
        out.push_str(&"---|".repeat(names.len()));
        out.push('\n');
        for row in &ablations.rows {
            let sindy = if metric == "gen" {
                row.sindy.generalisation
            } else {
                row.sindy.adaptation
            };
            out.push_str(&format!(
                "| {} | {} | {sindy:.3} |",
                row.table, row.condition
            ));
            for name in &names {
                let cell = &row.variants[*name];
                let (mean, std) = if metric == "gen" {
                    (cell.r#gen, cell.gen_std)
                } else {
                    (cell.adapt, cell.adapt_std)
                };
                out.push_str(&format!(" {mean:.3} ± {std:.3} |"));
            }
            out.push('\n');
        }
        out.push('\n');
    }
    if ablations
        .rows
        .iter()
        .any(|r| !r.headline_equations.is_empty())
    {
        let name = config
            .equations_variant(&config.headline)
            .unwrap_or(&config.headline);
        let role = if name == config.headline {
            String::new()
        } else {
            format!(
                " (the regression member of the headline `{}`)",
                config.headline
            )
        };
        out.push_str(&format!(
            "## `{name}` equations{role} (seed {}), the five largest terms\n\n\
             Terms ordered by standardised coefficient; every term is in `ablations.json`.\n\n",
            config.seeds.first().copied().unwrap_or_default()
        ));
        for row in &ablations.rows {
            out.push_str(&format!("- {} {}:\n", row.table, row.condition));
            for equation in &row.headline_equations {
                let shown = shorten(equation, 5);
                out.push_str(&format!("  - `{shown}`\n"));
            }
        }
        out.push('\n');
    }
    out.push_str("## Variants\n\n");
    for variant in &config.variants {
        out.push_str(&format!("- `{}`: {}\n", variant.name, variant.description));
    }
    out
}

/// The intercept and the first `terms` terms of an equation of `headline_equations`.
fn shorten(equation: &str, terms: usize) -> String {
    let words: Vec<&str> = equation.split(' ').collect();
    // "out = b" then groups of three words: sign, coefficient, feature.
    let keep = (3 + 3 * terms).min(words.len());
    let mut text = words[..keep].join(" ");
    if keep < words.len() {
        text.push_str(" …");
    }
    text
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn equations_are_shortened_to_their_largest_terms() {
        let equation = "vdot_x = 0.1000 + 2.0000 a - 1.0000 b + 0.5000 c";
        assert_eq!(
            shorten(equation, 2),
            "vdot_x = 0.1000 + 2.0000 a - 1.0000 b …"
        );
        assert_eq!(shorten(equation, 3), equation);
    }
}
