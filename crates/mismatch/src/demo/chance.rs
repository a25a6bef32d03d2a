//! How far a recording's information reaches: the probability that an unbiased estimate, scattering
//! as its standard errors say, lands within a parameter's target. A miss where this is near 1 is
//! the estimate's fault; where it is well below 1, no estimator this precise meets the target
//! reliably on that recording.

use statrs::function::erf::erf;
use std::f64::consts::{FRAC_1_SQRT_2, FRAC_PI_2, PI};

/// Grid points per integrated component; the probabilities below are exact to about 10⁻⁶ for up
/// to three components.
const GRID_POINTS: usize = 200;
/// Standard deviations beyond which a component's density is taken as zero.
const DENSITY_REACH: f64 = 8.0;

/// `P(‖e‖ ≤ limit)` for `e` with independent normal components of mean zero and standard
/// deviations `sigma`: the widest component in closed form, `erf(√(limit² − Σ σᵢ²zᵢ²) / (σ√2))`,
/// the others integrated over their standard normal `zᵢ` inside the ball (`zᵢ = r sin θ`, so that
/// the integrand stays smooth at the ball's edge). Components with a zero standard deviation are
/// exact; `None` when a standard deviation or the limit is not a finite non-negative number.
pub fn chance_within(limit: f64, sigma: &[f64]) -> Option<f64> {
    let valid = |x: f64| x.is_finite() && x >= 0.0;
    if !valid(limit) || !sigma.iter().all(|s| valid(*s)) {
        return None;
    }
    let mut spread: Vec<f64> = sigma.iter().copied().filter(|s| *s > 0.0).collect();
    spread.sort_by(|a, b| b.total_cmp(a));
    let Some((&widest, rest)) = spread.split_first() else {
        return Some(1.0);
    };
    Some(integrate(limit * limit, rest, widest).clamp(0.0, 1.0))
}

/// `E[P(σ_w² z² ≤ remaining − Σ_{rest} σᵢ² zᵢ²)]` over the `rest`'s components.
fn integrate(remaining: f64, rest: &[f64], widest: f64) -> f64 {
    if remaining <= 0.0 {
        return 0.0;
    }
    let Some((&sigma, others)) = rest.split_first() else {
        return erf(remaining.sqrt() / widest * FRAC_1_SQRT_2);
    };
    let reach = (remaining.sqrt() / sigma).min(DENSITY_REACH);
    let step = PI / GRID_POINTS as f64;
    (0..GRID_POINTS)
        .map(|j| {
            let angle = -FRAC_PI_2 + (j as f64 + 0.5) * step;
            let z = reach * angle.sin();
            let density = (-0.5 * z * z).exp() / (2.0 * PI).sqrt();
            let weight = density * reach * angle.cos() * step;
            weight * integrate(remaining - (sigma * z).powi(2), others, widest)
        })
        .sum()
}

#[cfg(test)]
mod tests {
    use super::chance_within;
    use statrs::distribution::{ChiSquared, ContinuousCDF};

    #[test]
    fn one_component_is_the_two_sided_normal() {
        // P(|z| ≤ 1.96) = 0.95.
        let p = chance_within(1.96 * 0.3, &[0.3]).unwrap();
        assert!((p - 0.9500).abs() < 1e-4, "{p}");
    }

    #[test]
    fn equal_components_follow_the_chi_square() {
        for (n, x) in [(2usize, 1.5f64), (3, 2.0), (3, 3.2)] {
            let sigma = 0.02;
            let p = chance_within(x * sigma, &vec![sigma; n]).unwrap();
            let exact = ChiSquared::new(n as f64).unwrap().cdf(x * x);
            assert!((p - exact).abs() < 1e-6, "n {n} x {x}: {p} against {exact}");
        }
    }

    #[test]
    fn a_narrow_component_barely_matters_and_an_exact_one_not_at_all() {
        let alone = chance_within(0.03, &[0.015]).unwrap();
        let with_exact = chance_within(0.03, &[0.0, 0.015, 0.0]).unwrap();
        let with_narrow = chance_within(0.03, &[1e-4, 0.015]).unwrap();
        assert!((alone - with_exact).abs() < 1e-12);
        assert!((alone - with_narrow).abs() < 1e-4 && with_narrow <= alone + 1e-12);
    }

    #[test]
    fn uneven_components_lie_between_their_bounds() {
        // Wider than the widest alone would allow, narrower than all at the widest.
        let p = chance_within(0.0328, &[0.0051, 0.0092, 0.0164]).unwrap();
        let widest_alone = chance_within(0.0328, &[0.0164]).unwrap();
        let all_widest = chance_within(0.0328, &[0.0164; 3]).unwrap();
        assert!(
            all_widest < p && p < widest_alone,
            "{all_widest} {p} {widest_alone}"
        );
    }

    #[test]
    fn nonsense_gives_none() {
        assert_eq!(chance_within(f64::NAN, &[0.1]), None);
        assert_eq!(chance_within(0.1, &[-0.1]), None);
        assert_eq!(chance_within(0.1, &[f64::INFINITY]), None);
        assert_eq!(chance_within(0.1, &[]), Some(1.0));
    }
}
