//! The variants made of other variants' results, none of which fits anything: `select` (the
//! candidate with the lowest support cross-validation error), `average` (the members' mean
//! prediction) and the mean of a `learn_ensemble`'s members. Nothing here reads the query segment
//! but to score.

use crate::segment::Segment;
use crate::sindy_variant::SegmentPredictions;
use sindy::Mat;

use crate::runner::Outcome;

/// `select`: of the `candidates` (indices into `names` and `outcomes`, at least one), the one
/// with the lowest support cross-validation score, its name recorded as chosen.
pub(super) fn select(names: &[&str], outcomes: &[Outcome], candidates: &[usize]) -> Outcome {
    let score = |index: usize| outcomes[index].support_cv.unwrap_or(f64::INFINITY);
    let best = candidates
        .iter()
        .copied()
        .min_by(|&a, &b| score(a).total_cmp(&score(b)))
        .expect("at least one candidate");
    let chosen_outcome = &outcomes[best];
    let mut chosen = chosen_outcome.chosen.clone();
    chosen.insert(
        "variant".to_string(),
        report::Choice::Variant(names[best].to_string()),
    );
    Outcome {
        chosen,
        ..chosen_outcome.clone()
    }
}

/// `average`: the mean of the `members`' predictions (at least one), equal weights.
pub(super) fn average(
    members: &[&SegmentPredictions],
    support: &Segment,
    query: &Segment,
) -> Outcome {
    let mean = |prediction: fn(&SegmentPredictions) -> &Mat<f64>| {
        let first = prediction(members[0]);
        Mat::from_fn(first.nrows(), first.ncols(), |i, j| {
            members.iter().map(|m| prediction(m)[(i, j)]).sum::<f64>() / members.len() as f64
        })
    };
    Outcome::unfitted(
        mean(|e| &e.support_prediction),
        mean(|e| &e.query_prediction),
        support,
        query,
    )
}

/// A `learn_ensemble`: the mean of its members' [support, query] predictions (at least one), summed
/// in member order and then scaled.
pub(super) fn ensemble_mean(
    members: impl IntoIterator<Item = [Mat<f64>; 2]>,
    support: &Segment,
    query: &Segment,
) -> Outcome {
    let mut count = 0usize;
    let mut sums: Option<[Mat<f64>; 2]> = None;
    for predictions in members {
        count += 1;
        match &mut sums {
            None => sums = Some(predictions),
            Some(sums) => {
                for (sum, prediction) in sums.iter_mut().zip(&predictions) {
                    *sum += prediction;
                }
            }
        }
    }
    let scale = 1.0 / count as f64;
    let [on_support, on_query] = sums.expect("at least one member");
    Outcome::unfitted(
        Mat::from_fn(on_support.nrows(), on_support.ncols(), |i, j| {
            on_support[(i, j)] * scale
        }),
        Mat::from_fn(on_query.nrows(), on_query.ncols(), |i, j| {
            on_query[(i, j)] * scale
        }),
        support,
        query,
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::variants::testing::segment;

    fn outcome(support_cv: Option<f64>, value: f64, support: &Segment, query: &Segment) -> Outcome {
        let constant = |segment: &Segment| Mat::from_fn(segment.len(), 3, |_, _| value);
        Outcome {
            support_cv,
            ..Outcome::unfitted(constant(support), constant(query), support, query)
        }
    }

    #[test]
    fn select_takes_the_lowest_support_score_and_average_and_ensemble_the_mean() {
        let (support, query) = (segment(20, 0.0), segment(10, 1.3));
        let outcomes = [
            outcome(Some(2.0), 1.0, &support, &query),
            outcome(Some(0.5), 2.0, &support, &query),
            outcome(None, 4.0, &support, &query),
        ];
        let selected = select(&["a", "b", "c"], &outcomes, &[0, 1, 2]);
        assert_eq!(
            selected.chosen["variant"],
            report::Choice::Variant("b".to_string())
        );
        assert_eq!(selected.predictions.query_prediction[(0, 0)], 2.0);

        let members = [&outcomes[0].predictions, &outcomes[2].predictions];
        let mean = average(&members, &support, &query);
        assert_eq!(mean.predictions.support_prediction[(3, 1)], 2.5);
        assert!(mean.chosen.is_empty() && mean.support_cv.is_none());

        let pair = |value: f64| {
            [&support, &query].map(|segment| Mat::from_fn(segment.len(), 3, |_, _| value))
        };
        let ensemble = ensemble_mean([pair(1.0), pair(2.0), pair(6.0)], &support, &query);
        assert_eq!(ensemble.predictions.query_prediction[(9, 2)], 3.0);
        assert_eq!(ensemble.predictions.query_prediction.nrows(), query.len());
    }
}
