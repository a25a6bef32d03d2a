//! The one median of the robust scales (statrs' order statistic): the noise of fourth differences
//! ([`crate::weak_form`]) and, in the mismatch analysis, the spread of residuals and of command
//! departures and the typical size of a target. Of an even count it is the larger of the two middle
//! values. [`robust_standard_deviation`] is the one median-absolute-deviation scale of them.

use statrs::statistics::{Data, OrderStatistics};

/// The median absolute deviation's factor to a normal standard deviation: 1 / Φ⁻¹(3/4).
pub const MAD_TO_STANDARD_DEVIATION: f64 = 1.482_602_218_505_602;

/// The robust standard deviation of deviations from a centre (or of residuals): the median of
/// their magnitudes times [`MAD_TO_STANDARD_DEVIATION`], so that normal noise gives its σ.
pub fn robust_standard_deviation(deviations: impl IntoIterator<Item = f64>) -> f64 {
    MAD_TO_STANDARD_DEVIATION * median(deviations.into_iter().map(f64::abs).collect())
}

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
    use statrs::distribution::{ContinuousCDF, Normal};

    #[test]
    fn the_mad_factor_is_one_over_the_normal_upper_quartile() {
        let quartile = Normal::standard().inverse_cdf(0.75);
        assert!((MAD_TO_STANDARD_DEVIATION - 1.0 / quartile).abs() < 1e-12);
        assert_eq!(
            robust_standard_deviation([-2.0, 1.0, 3.0]),
            2.0 * MAD_TO_STANDARD_DEVIATION
        );
    }

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
