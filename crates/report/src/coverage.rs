//! The note under a results table on the query samples outside the range of the LeARN
//! meta-training inputs (where the networks extrapolate), from each cell's counts and errors
//! ([`QueryCoverage`]).

/// One cell's query segment as the coverage note reports it.
#[derive(Clone, Debug, PartialEq)]
pub struct QueryCoverage {
    /// The condition as printed, e.g. `70psin20`.
    pub label: String,
    pub samples: usize,
    /// Samples with an input outside the range of the meta-training inputs.
    pub samples_outside: usize,
    /// The input that goes farthest outside its range, if any sample is outside.
    pub farthest: Option<FarthestInput>,
    /// Each method's generalisation MSE over the query samples inside and outside the range
    /// (LeARN's averaged over seeds), when both are known.
    pub learn_inside_outside: Option<(f64, f64)>,
    pub sindy_inside_outside: Option<(f64, f64)>,
}

/// The input of a cell that goes farthest outside the range of the meta-training inputs.
#[derive(Clone, Debug, PartialEq)]
pub struct FarthestInput {
    pub input: String,
    /// How far beyond the range, in standard deviations of the meta-training inputs.
    pub largest_excess_in_std: f64,
    pub samples_outside: usize,
    /// What the samples outside on this input add to each method's generalisation MSE.
    pub learn_added: Option<f64>,
    pub sindy_added: Option<f64>,
}

/// The note under a table: per cell with a range (`None`: the cell has none), how many query
/// samples lie outside it, naming the input that goes farthest, with LeARN's and SINDy's
/// generalisation MSE over the samples inside and outside that range; `None` if no cell has a
/// range.
pub fn coverage_note(cells: &[Option<QueryCoverage>]) -> Option<String> {
    let parts: Vec<String> = cells.iter().flatten().map(cell_part).collect();
    (!parts.is_empty()).then(|| {
        format!(
            "LeARN query samples with an input outside the range of the meta-training inputs \
             (the networks extrapolate there), with the generalisation MSE of each method over the \
             query samples inside and outside that range: {}.",
            parts.join("; ")
        )
    })
}

/// One cell's part of the note, e.g. `100wind 3 of 10 (farthest: w_z by 9.6 std on 3 samples,
/// which add 0.125 to LeARN's MSE; MSE inside / outside: LeARN 0.250 / 2.500)`.
fn cell_part(cell: &QueryCoverage) -> String {
    let split = |errors: Option<(f64, f64)>| {
        errors.map(|(inside, outside)| format!("{inside:.3} / {outside:.3}"))
    };
    let errors = match (
        split(cell.learn_inside_outside),
        split(cell.sindy_inside_outside),
    ) {
        (Some(learn), Some(sindy)) => {
            format!("; MSE inside / outside: LeARN {learn}, SINDy {sindy}")
        }
        (Some(learn), None) => format!("; MSE inside / outside: LeARN {learn}"),
        _ => String::new(),
    };
    let detail = cell.farthest.as_ref().map_or(String::new(), |input| {
        format!(
            " (farthest: {} by {:.1} std on {} samples{}{errors})",
            input.input,
            input.largest_excess_in_std,
            input.samples_outside,
            contributions(input)
        )
    });
    format!(
        "{} {} of {}{detail}",
        cell.label, cell.samples_outside, cell.samples
    )
}

/// What the samples outside on `input` add to each method's generalisation MSE, e.g. ", which
/// add 0.126 to LeARN's MSE and 0.020 to SINDy's"; empty without LeARN's.
fn contributions(input: &FarthestInput) -> String {
    let Some(learn) = input.learn_added else {
        return String::new();
    };
    match input.sindy_added {
        Some(sindy) => {
            format!(", which add {learn:.3} to LeARN's MSE and {sindy:.3} to SINDy's")
        }
        None => format!(", which add {learn:.3} to LeARN's MSE"),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_note_names_the_farthest_input_and_the_errors_it_knows() {
        let farthest = FarthestInput {
            input: "w_z".to_string(),
            largest_excess_in_std: 9.61,
            samples_outside: 3,
            learn_added: Some(0.125),
            sindy_added: None,
        };
        let cells = [
            Some(QueryCoverage {
                label: "35wind".to_string(),
                samples: 10,
                samples_outside: 0,
                farthest: None,
                learn_inside_outside: Some((0.5, 1.0)),
                sindy_inside_outside: None,
            }),
            None,
            Some(QueryCoverage {
                label: "70wind".to_string(),
                samples: 10,
                samples_outside: 3,
                farthest: Some(farthest),
                learn_inside_outside: None,
                sindy_inside_outside: Some((0.5, 1.25)),
            }),
        ];
        let note = coverage_note(&cells).unwrap();
        assert!(
            note.ends_with(
                ": 35wind 0 of 10; 70wind 3 of 10 (farthest: w_z by 9.6 std on 3 samples, which add 0.125 to LeARN's MSE)."
            ),
            "{note}"
        );
        assert_eq!(coverage_note(&[None]), None);
    }
}
