//! The scalar types the networks are generic over: `f64` for values and gradients, [`Dual`] for
//! Hessian-vector products (forward-over-reverse: the reverse pass run on dual numbers).

use std::ops::{Add, AddAssign, Mul, Neg, Sub};

/// 1/√2.
const FRAC_1_SQRT_2: f64 = std::f64::consts::FRAC_1_SQRT_2;
/// 1/√(2π).
const FRAC_1_SQRT_2PI: f64 = 0.398_942_280_401_432_7;

/// The exact (erf) GELU: x·Φ(x).
pub fn gelu(x: f64) -> f64 {
    0.5 * x * (1.0 + libm::erf(x * FRAC_1_SQRT_2))
}

/// GELU′(x) = Φ(x) + x·φ(x).
pub fn gelu_derivative(x: f64) -> f64 {
    let cdf = 0.5 * (1.0 + libm::erf(x * FRAC_1_SQRT_2));
    let pdf = FRAC_1_SQRT_2PI * (-0.5 * x * x).exp();
    cdf + x * pdf
}

/// GELU″(x) = φ(x)·(2 − x²).
pub fn gelu_second_derivative(x: f64) -> f64 {
    FRAC_1_SQRT_2PI * (-0.5 * x * x).exp() * (2.0 - x * x)
}

/// What the forward and backward passes need from a number.
pub trait Scalar:
    Copy
    + Send
    + Sync
    + Default
    + std::fmt::Debug
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<Output = Self>
    + Neg<Output = Self>
    + AddAssign
    + 'static
{
    /// A constant (zero tangent).
    fn constant(value: f64) -> Self;
    /// The value part.
    fn value(self) -> f64;
    /// Multiplication by a plain number.
    fn scale(self, factor: f64) -> Self;
    /// (GELU(self), GELU′(self)), with one erf and one exp.
    fn gelu_and_derivative(self) -> (Self, Self);
}

/// (Φ(x), φ(x)): the standard normal distribution and density.
#[inline(always)]
fn normal_cdf_and_pdf(x: f64) -> (f64, f64) {
    (
        0.5 * (1.0 + libm::erf(x * FRAC_1_SQRT_2)),
        FRAC_1_SQRT_2PI * (-0.5 * x * x).exp(),
    )
}

impl Scalar for f64 {
    #[inline(always)]
    fn constant(value: f64) -> Self {
        value
    }
    #[inline(always)]
    fn value(self) -> f64 {
        self
    }
    #[inline(always)]
    fn scale(self, factor: f64) -> Self {
        self * factor
    }
    #[inline(always)]
    fn gelu_and_derivative(self) -> (Self, Self) {
        let (cdf, pdf) = normal_cdf_and_pdf(self);
        (self * cdf, cdf + self * pdf)
    }
}

/// A dual number value + ε·tangent with ε² = 0: carrying a direction v through the gradient
/// computation yields the Hessian-vector product H·v in the tangent parts.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Dual {
    pub value: f64,
    pub tangent: f64,
}

impl Dual {
    pub fn new(value: f64, tangent: f64) -> Self {
        Self { value, tangent }
    }
}

impl Add for Dual {
    type Output = Self;
    #[inline(always)]
    fn add(self, other: Self) -> Self {
        Self::new(self.value + other.value, self.tangent + other.tangent)
    }
}

impl Sub for Dual {
    type Output = Self;
    #[inline(always)]
    fn sub(self, other: Self) -> Self {
        Self::new(self.value - other.value, self.tangent - other.tangent)
    }
}

impl Mul for Dual {
    type Output = Self;
    #[inline(always)]
    fn mul(self, other: Self) -> Self {
        Self::new(
            self.value * other.value,
            self.value * other.tangent + self.tangent * other.value,
        )
    }
}

impl Neg for Dual {
    type Output = Self;
    #[inline(always)]
    fn neg(self) -> Self {
        Self::new(-self.value, -self.tangent)
    }
}

impl AddAssign for Dual {
    #[inline(always)]
    fn add_assign(&mut self, other: Self) {
        self.value += other.value;
        self.tangent += other.tangent;
    }
}

impl Scalar for Dual {
    #[inline(always)]
    fn constant(value: f64) -> Self {
        Self::new(value, 0.0)
    }
    #[inline(always)]
    fn value(self) -> f64 {
        self.value
    }
    #[inline(always)]
    fn scale(self, factor: f64) -> Self {
        Self::new(self.value * factor, self.tangent * factor)
    }
    #[inline(always)]
    fn gelu_and_derivative(self) -> (Self, Self) {
        let x = self.value;
        let (cdf, pdf) = normal_cdf_and_pdf(x);
        let first = cdf + x * pdf;
        let second = pdf * (2.0 - x * x);
        (
            Self::new(x * cdf, first * self.tangent),
            Self::new(first, second * self.tangent),
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn gelu_derivatives_match_finite_differences() {
        let h = 1e-5;
        for &x in &[-3.0, -1.2, -0.3, 0.0, 0.4, 1.7, 4.0] {
            let first = (gelu(x + h) - gelu(x - h)) / (2.0 * h);
            let second = (gelu_derivative(x + h) - gelu_derivative(x - h)) / (2.0 * h);
            assert!((first - gelu_derivative(x)).abs() < 1e-9, "x = {x}");
            assert!((second - gelu_second_derivative(x)).abs() < 1e-9, "x = {x}");
        }
        // Known values of the exact GELU (not the tanh approximation).
        assert!((gelu(1.0) - 0.841_344_746_068_542_9).abs() < 1e-15);
        assert!((gelu(-1.0) + 0.158_655_253_931_457_05).abs() < 1e-15);
    }

    #[test]
    fn dual_numbers_carry_first_derivatives() {
        let x = Dual::new(0.7, 1.0);
        let (g, g_prime) = x.gelu_and_derivative();
        let y = x * g - x.scale(3.0);
        let exact = gelu(0.7) + 0.7 * gelu_derivative(0.7) - 3.0;
        assert!((y.tangent - exact).abs() < 1e-14);
        assert!((g_prime.tangent - gelu_second_derivative(0.7)).abs() < 1e-15);
        let (value, derivative) = 0.7f64.gelu_and_derivative();
        assert!(
            (value - gelu(0.7)).abs() < 1e-16 && (derivative - gelu_derivative(0.7)).abs() < 1e-16
        );
    }
}
