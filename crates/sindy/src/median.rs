//! The one median of the robust scales (statrs' order statistic): the noise of fourth differences
//! ([`crate::weak_form`]) and, in the mismatch analysis, the spread of residuals and of command
//! departures and the typical size of a target. Of an even count it is the larger of the two middle
//! values.

use statrs::statistics::{Data, OrderStatistics};

/// The median of `values`: of an even count the larger middle value (statrs' order statistic
/// n/2 + 1); 0 for none.
pub fn median(values: Vec<f64>) -> f64 {
    if values.is_empty() {
        return 0.0;
    }
    let order = values.len() / 2 + 1;
    Data::new(values).order_statistic(order)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The convention the analysis's numbers were made with: the upper middle value, NaN last.
    #[test]
    fn the_median_of_an_even_count_is_the_upper_middle_value() {
        assert_eq!(median(vec![3.0, 1.0, 2.0]), 2.0);
        assert_eq!(median(vec![4.0, 1.0, 2.0, 3.0]), 3.0);
        assert_eq!(median(vec![2.0, 1.0]), 2.0);
        assert_eq!(median(vec![5.0]), 5.0);
        assert_eq!(median(Vec::new()), 0.0);
        assert_eq!(median(vec![f64::NAN, 1.0, 3.0, 2.0]), 3.0);
    }
}
