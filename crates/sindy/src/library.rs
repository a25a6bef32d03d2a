//! Feature libraries Θ(X): the candidate terms a sparse model chooses from.
//!
//! Feature names (used by equations, the CLI and the model JSON):
//! - constant `1`;
//! - monomials: factors in input order joined by `*`, powers as `^p`: `x`, `x^2`, `x*y`, `x^2*u`;
//! - Fourier: `sin(x)`, `cos(x)`, `sin(2*x)`, `cos(2*x)`;
//! - custom: the function's name template with `{}` replaced by the input name, e.g. `exp(x)`.
//!
//! Feature order follows PySINDy: polynomial terms degree by degree (constant first), within a
//! degree the combinations with replacement of the inputs in lexicographic order (scikit-learn's
//! `PolynomialFeatures`); Fourier terms frequency by frequency, and for each input `sin` then `cos`
//! (`sin(x0), cos(x0), sin(x1), cos(x1), …, sin(2*x0), …`); concatenations part by part.

use std::fmt;
use std::sync::Arc;

use faer::{Mat, MatRef};
use serde::{Deserialize, Serialize};

use crate::error::{Result, SindyError, invalid};

/// The most features a library may have on the inputs it is applied to (polynomial, Fourier,
/// custom and concatenated libraries, and the `evaluation` crate's causal library). It is checked on
/// the feature count computed in closed form, before any feature is enumerated or any Θ(X)
/// allocated. Far above every committed configuration (the paper's library, Fourier K = 1, has
/// 2·K·n = 20 features on the 10 inputs of the full formulation; the largest committed variant
/// library 42), and low enough that a flight's Θ stays within hundreds of MB.
pub const MAX_FEATURES: usize = 10_000;

/// A serialisable description of a library made of polynomial and Fourier parts.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
pub enum LibrarySpec {
    /// All monomials of the inputs up to `degree`, with the constant `1` if `constant`.
    Polynomial { degree: usize, constant: bool },
    /// `sin(k·z)` and `cos(k·z)` of every input z, for k = 1..=frequencies.
    Fourier { frequencies: usize },
    /// The features of each part, one part after the other.
    Concatenation { parts: Vec<LibrarySpec> },
}

impl LibrarySpec {
    /// Parses the command-line form: parts joined by `+`, each `poly:D` (with constant),
    /// `poly:D:noconstant` or `fourier:K`. Example: `poly:2+fourier:1`.
    pub fn parse(text: &str) -> Result<Self> {
        let error = |message: String| SindyError::Parse {
            kind: "library",
            text: text.to_string(),
            message,
        };
        let mut parts = Vec::new();
        for part in text.split('+').map(str::trim) {
            let fields: Vec<&str> = part.split(':').collect();
            let number = |index: usize| -> Result<usize> {
                let field = fields.get(index).ok_or_else(|| {
                    error(format!("'{part}' needs a number, e.g. poly:2 or fourier:1"))
                })?;
                field
                    .parse()
                    .map_err(|_| error(format!("'{field}' in '{part}' is not a whole number")))
            };
            let spec = match (fields[0], fields.len()) {
                ("poly", 2) => Self::Polynomial {
                    degree: number(1)?,
                    constant: true,
                },
                ("poly", 3) if fields[2] == "noconstant" => Self::Polynomial {
                    degree: number(1)?,
                    constant: false,
                },
                ("fourier", 2) => Self::Fourier {
                    frequencies: number(1)?,
                },
                _ => {
                    return Err(error(format!(
                        "unknown part '{part}' (known: poly:D, poly:D:noconstant, fourier:K)"
                    )));
                }
            };
            parts.push(spec);
        }
        let spec = if parts.len() == 1 {
            parts.remove(0)
        } else {
            Self::Concatenation { parts }
        };
        spec.validate()?;
        Ok(spec)
    }

    /// Number of features on `inputs` input variables, in closed form (nothing is enumerated):
    /// C(n + d, d) monomials of n inputs up to degree d (one fewer without the constant), 2·K·n
    /// Fourier terms, the sum over the parts of a concatenation. `None` if it overflows `usize`.
    pub fn feature_count(&self, inputs: usize) -> Option<usize> {
        match self {
            Self::Polynomial { degree, constant } => polynomial_count(inputs, *degree, *constant),
            Self::Fourier { frequencies } => frequencies.checked_mul(inputs)?.checked_mul(2),
            Self::Concatenation { parts } => parts.iter().try_fold(0usize, |sum, part| {
                sum.checked_add(part.feature_count(inputs)?)
            }),
        }
    }

    /// Checks that every part yields at least one feature and that the library has at most
    /// [`MAX_FEATURES`] features on a single input (the count on the actual inputs is checked
    /// by [`FeatureLibrary::checked_feature_count`]).
    pub fn validate(&self) -> Result<()> {
        self.validate_parts()?;
        if self
            .feature_count(1)
            .is_none_or(|count| count > MAX_FEATURES)
        {
            return Err(invalid(
                &format!("library '{self}'"),
                format!(
                    "{} features on a single input already, more than the limit of \
                     {MAX_FEATURES} (sindy::MAX_FEATURES)",
                    count_text(self.feature_count(1))
                ),
            ));
        }
        Ok(())
    }

    fn validate_parts(&self) -> Result<()> {
        match self {
            Self::Polynomial { degree, constant } => {
                if *degree == 0 && !*constant {
                    return Err(invalid(
                        "polynomial library",
                        "degree 0 without constant has no feature",
                    ));
                }
            }
            Self::Fourier { frequencies } => {
                if *frequencies == 0 {
                    return Err(invalid("Fourier library", "frequencies must be at least 1"));
                }
            }
            Self::Concatenation { parts } => {
                if parts.is_empty() {
                    return Err(invalid(
                        "library",
                        "a concatenation needs at least one part",
                    ));
                }
                parts.iter().try_for_each(Self::validate_parts)?;
            }
        }
        Ok(())
    }
}

impl fmt::Display for LibrarySpec {
    /// The command-line form accepted by [`LibrarySpec::parse`].
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Polynomial {
                degree,
                constant: true,
            } => write!(f, "poly:{degree}"),
            Self::Polynomial {
                degree,
                constant: false,
            } => write!(f, "poly:{degree}:noconstant"),
            Self::Fourier { frequencies } => write!(f, "fourier:{frequencies}"),
            Self::Concatenation { parts } => {
                for (i, part) in parts.iter().enumerate() {
                    if i > 0 {
                        write!(f, "+")?;
                    }
                    write!(f, "{part}")?;
                }
                Ok(())
            }
        }
    }
}

/// A named scalar function applied to every input, e.g. `exp({})`.
#[derive(Clone)]
pub struct CustomFunction {
    template: String,
    function: Arc<dyn Fn(f64) -> f64 + Send + Sync>,
}

impl CustomFunction {
    /// `template` names the feature, `{}` standing for the input's name (e.g. `exp({})`).
    pub fn new(
        template: impl Into<String>,
        function: impl Fn(f64) -> f64 + Send + Sync + 'static,
    ) -> Result<Self> {
        let template = template.into();
        if !template.contains("{}") {
            return Err(invalid(
                "custom feature",
                format!("name template '{template}' must contain {{}} for the input name"),
            ));
        }
        Ok(Self {
            template,
            function: Arc::new(function),
        })
    }

    fn name(&self, input: &str) -> String {
        self.template.replace("{}", input)
    }
}

impl fmt::Debug for CustomFunction {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "CustomFunction({})", self.template)
    }
}

#[derive(Clone, Debug)]
enum Part {
    Polynomial { degree: usize, constant: bool },
    Fourier { frequencies: usize },
    Custom(Vec<CustomFunction>),
}

/// A checked feature library: maps inputs X (one row per sample) to features Θ(X).
#[derive(Clone, Debug)]
pub struct FeatureLibrary {
    parts: Vec<Part>,
}

impl FeatureLibrary {
    /// Builds the library a specification describes.
    pub fn from_spec(spec: &LibrarySpec) -> Result<Self> {
        spec.validate()?;
        let mut parts = Vec::new();
        collect_parts(spec, &mut parts);
        Ok(Self { parts })
    }

    /// A library of custom functions, each applied to every input.
    pub fn custom(functions: Vec<CustomFunction>) -> Result<Self> {
        if functions.is_empty() {
            return Err(invalid("custom library", "needs at least one function"));
        }
        Ok(Self {
            parts: vec![Part::Custom(functions)],
        })
    }

    /// This library's features followed by `other`'s.
    pub fn concat(mut self, other: FeatureLibrary) -> Self {
        self.parts.extend(other.parts);
        self
    }

    /// The specification of this library, or `None` if it has custom functions (closures cannot be
    /// written to a file).
    pub fn spec(&self) -> Option<LibrarySpec> {
        let mut specs = Vec::with_capacity(self.parts.len());
        for part in &self.parts {
            specs.push(match part {
                Part::Polynomial { degree, constant } => LibrarySpec::Polynomial {
                    degree: *degree,
                    constant: *constant,
                },
                Part::Fourier { frequencies } => LibrarySpec::Fourier {
                    frequencies: *frequencies,
                },
                Part::Custom(_) => return None,
            });
        }
        Some(if specs.len() == 1 {
            specs.remove(0)
        } else {
            LibrarySpec::Concatenation { parts: specs }
        })
    }

    /// Names of the features for inputs named `inputs`, in column order of [`Self::transform`].
    pub fn feature_names(&self, inputs: &[&str]) -> Vec<String> {
        let mut names = Vec::new();
        for part in &self.parts {
            match part {
                Part::Polynomial { degree, constant } => {
                    for term in monomials(inputs.len(), *degree, *constant) {
                        names.push(monomial_name(&term, inputs));
                    }
                }
                Part::Fourier { frequencies } => {
                    for k in 1..=*frequencies {
                        for input in inputs {
                            let argument = if k == 1 {
                                input.to_string()
                            } else {
                                format!("{k}*{input}")
                            };
                            names.push(format!("sin({argument})"));
                            names.push(format!("cos({argument})"));
                        }
                    }
                }
                Part::Custom(functions) => {
                    for function in functions {
                        for input in inputs {
                            names.push(function.name(input));
                        }
                    }
                }
            }
        }
        names
    }

    /// [`Self::feature_names`], failing when a name repeats (e.g. `poly:1+poly:2` has `x` twice, or
    /// an input named `x^2` next to `x`): a model's terms are identified by name, in its equations
    /// and in its file, so two columns of one name would be merged or lost.
    ///
    /// Fails without enumerating anything when the library has more than [`MAX_FEATURES`]
    /// features on these inputs.
    pub fn unique_feature_names(&self, inputs: &[&str]) -> Result<Vec<String>> {
        self.checked_feature_count(inputs.len())?;
        let names = self.feature_names(inputs);
        let mut seen = std::collections::HashSet::with_capacity(names.len());
        if let Some(repeated) = names.iter().find(|name| !seen.insert(name.as_str())) {
            return Err(invalid(
                &self.describe(),
                format!(
                    "it has the feature '{repeated}' twice on inputs {} (each feature must be unique)",
                    inputs.join(", ")
                ),
            ));
        }
        Ok(names)
    }

    /// Number of features for `inputs` input variables, in closed form (saturating at
    /// `usize::MAX`; see [`Self::checked_feature_count`] for the checked count).
    pub fn feature_count(&self, inputs: usize) -> usize {
        self.exact_feature_count(inputs).unwrap_or(usize::MAX)
    }

    /// The number of features for `inputs` input variables, failing (before anything is
    /// enumerated or allocated) when it exceeds [`MAX_FEATURES`].
    pub fn checked_feature_count(&self, inputs: usize) -> Result<usize> {
        match self.exact_feature_count(inputs) {
            Some(count) if count <= MAX_FEATURES => Ok(count),
            count => Err(invalid(
                &self.describe(),
                format!(
                    "{} features on {inputs} inputs, more than the limit of {MAX_FEATURES} \
                     (sindy::MAX_FEATURES)",
                    count_text(count)
                ),
            )),
        }
    }

    /// `None` if the count overflows `usize`.
    fn exact_feature_count(&self, inputs: usize) -> Option<usize> {
        self.parts.iter().try_fold(0usize, |sum, part| {
            let count = match part {
                Part::Polynomial { degree, constant } => {
                    polynomial_count(inputs, *degree, *constant)?
                }
                Part::Fourier { frequencies } => frequencies.checked_mul(inputs)?.checked_mul(2)?,
                Part::Custom(functions) => functions.len().checked_mul(inputs)?,
            };
            sum.checked_add(count)
        })
    }

    /// `library 'poly:2'`, or `library` for one with custom functions.
    fn describe(&self) -> String {
        self.spec()
            .map_or_else(|| "library".to_string(), |spec| format!("library '{spec}'"))
    }

    /// Θ(X): one row per sample of `inputs`, one column per feature.
    ///
    /// ```
    /// use sindy::{FeatureLibrary, LibrarySpec, Mat};
    /// let library = FeatureLibrary::from_spec(&LibrarySpec::parse("poly:2")?)?;
    /// assert_eq!(library.feature_names(&["x", "u"]), ["1", "x", "u", "x^2", "x*u", "u^2"]);
    /// let theta = library.transform(Mat::from_fn(1, 2, |_, j| [3.0, 2.0][j]).as_ref());
    /// assert_eq!(theta[(0, 4)], 6.0);
    /// # Ok::<(), sindy::SindyError>(())
    /// ```
    pub fn transform(&self, inputs: MatRef<'_, f64>) -> Mat<f64> {
        let mut theta = Mat::new();
        self.transform_into(inputs, &mut theta);
        theta
    }

    /// [`Self::transform`] into `theta`, resized to fit (its memory reused when it holds enough:
    /// a block loop allocates Θ once); every entry is written.
    pub(crate) fn transform_into(&self, inputs: MatRef<'_, f64>, theta: &mut Mat<f64>) {
        crate::linalg::clear_upper_vector_state();
        let (n, dim) = (inputs.nrows(), inputs.ncols());
        let columns: Vec<Vec<f64>> = (0..dim)
            .map(|j| inputs.col(j).iter().copied().collect())
            .collect();
        theta.resize_with(n, self.feature_count(dim), |_, _| 0.0);
        let mut next = 0;
        let mut cosines = vec![0.0; n];
        for part in &self.parts {
            match part {
                Part::Polynomial { degree, constant } => {
                    for term in monomials(dim, *degree, *constant) {
                        let out = column_slice(theta, next);
                        next += 1;
                        out.fill(1.0);
                        for &j in &term {
                            out.iter_mut().zip(&columns[j]).for_each(|(o, x)| *o *= x);
                        }
                    }
                }
                Part::Fourier { frequencies } => {
                    for k in 1..=*frequencies {
                        let k = k as f64;
                        for input in &columns {
                            let sines = column_slice(theta, next);
                            for ((sine, cosine), x) in sines.iter_mut().zip(&mut cosines).zip(input)
                            {
                                (*sine, *cosine) = (k * x).sin_cos();
                            }
                            column_slice(theta, next + 1).copy_from_slice(&cosines);
                            next += 2;
                        }
                    }
                }
                Part::Custom(functions) => {
                    for function in functions {
                        for input in &columns {
                            let out = column_slice(theta, next);
                            next += 1;
                            out.iter_mut()
                                .zip(input)
                                .for_each(|(o, &x)| *o = (function.function)(x));
                        }
                    }
                }
            }
        }
    }

    /// Θ of one sample `x`, written into `out` (cleared first). Used by simulation.
    pub(crate) fn transform_row(&self, x: &[f64], out: &mut Vec<f64>) {
        out.clear();
        for part in &self.parts {
            match part {
                Part::Polynomial { degree, constant } => {
                    for term in monomials(x.len(), *degree, *constant) {
                        out.push(term.iter().map(|&j| x[j]).product());
                    }
                }
                Part::Fourier { frequencies } => {
                    for k in 1..=*frequencies {
                        for value in x {
                            let (sin, cos) = (k as f64 * value).sin_cos();
                            out.push(sin);
                            out.push(cos);
                        }
                    }
                }
                Part::Custom(functions) => {
                    for function in functions {
                        out.extend(x.iter().map(|&v| (function.function)(v)));
                    }
                }
            }
        }
    }
}

/// Column `j` of a freshly allocated (column-major, contiguous) matrix as a slice.
fn column_slice(matrix: &mut Mat<f64>, j: usize) -> &mut [f64] {
    matrix
        .col_mut(j)
        .try_as_col_major_mut()
        .expect("owned matrices store columns contiguously")
        .as_slice_mut()
}

fn collect_parts(spec: &LibrarySpec, parts: &mut Vec<Part>) {
    match spec {
        LibrarySpec::Polynomial { degree, constant } => parts.push(Part::Polynomial {
            degree: *degree,
            constant: *constant,
        }),
        LibrarySpec::Fourier { frequencies } => parts.push(Part::Fourier {
            frequencies: *frequencies,
        }),
        LibrarySpec::Concatenation { parts: specs } => {
            specs.iter().for_each(|s| collect_parts(s, parts));
        }
    }
}

/// C(n + d, d) (the monomials of n inputs up to degree d, the constant included), minus one
/// without the constant; `None` if it overflows. Computed as C(n + d, k) with k = min(n, d), each
/// partial product C(n + d − k + i, i) an integer; it at least doubles with every step, so the loop
/// ends (by overflow) within about 128 steps whatever n and d are.
fn polynomial_count(inputs: usize, degree: usize, constant: bool) -> Option<usize> {
    let k = inputs.min(degree);
    let base = inputs.max(degree) as u128;
    let mut count: u128 = 1;
    for i in 1..=k as u128 {
        count = count.checked_mul(base + i)? / i;
    }
    usize::try_from(count - u128::from(!constant)).ok()
}

/// A feature count for a message: the number, or "more than" the largest `usize`.
fn count_text(count: Option<usize>) -> String {
    count.map_or_else(|| format!("more than {}", usize::MAX), |c| c.to_string())
}

/// The monomials of `dim` inputs up to `degree`, each as the sorted list of its factors' input
/// indices (empty = the constant), in scikit-learn's `PolynomialFeatures` order.
fn monomials(dim: usize, degree: usize, constant: bool) -> Vec<Vec<usize>> {
    let mut terms = Vec::new();
    if constant {
        terms.push(Vec::new());
    }
    for d in 1..=degree {
        combinations_with_replacement(dim, d, 0, &mut Vec::with_capacity(d), &mut terms);
    }
    terms
}

fn combinations_with_replacement(
    dim: usize,
    remaining: usize,
    start: usize,
    current: &mut Vec<usize>,
    out: &mut Vec<Vec<usize>>,
) {
    if remaining == 0 {
        out.push(current.clone());
        return;
    }
    for j in start..dim {
        current.push(j);
        combinations_with_replacement(dim, remaining - 1, j, current, out);
        current.pop();
    }
}

fn monomial_name(term: &[usize], inputs: &[&str]) -> String {
    if term.is_empty() {
        return "1".to_string();
    }
    let mut factors = Vec::new();
    let mut k = 0;
    while k < term.len() {
        let power = term[k..].iter().take_while(|&&j| j == term[k]).count();
        let name = inputs[term[k]];
        factors.push(if power == 1 {
            name.to_string()
        } else {
            format!("{name}^{power}")
        });
        k += power;
    }
    factors.join("*")
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Θ written into a buffer that held a longer, wider block of other numbers is the fresh Θ:
    /// every entry is written (a block loop reuses one buffer).
    #[test]
    fn a_reused_buffer_gives_the_fresh_library() {
        let library =
            FeatureLibrary::from_spec(&LibrarySpec::parse("poly:3+fourier:1").unwrap()).unwrap();
        let long = Mat::from_fn(50, 4, |i, j| (i as f64 - 7.0) * 0.1 + j as f64);
        let short = Mat::from_fn(20, 3, |i, j| 0.05 * i as f64 - 0.3 * j as f64);
        let mut buffer = Mat::new();
        library.transform_into(long.as_ref(), &mut buffer);
        library.transform_into(short.as_ref(), &mut buffer);
        let fresh = library.transform(short.as_ref());
        assert_eq!(
            (buffer.nrows(), buffer.ncols()),
            (fresh.nrows(), fresh.ncols())
        );
        for j in 0..fresh.ncols() {
            for i in 0..fresh.nrows() {
                assert_eq!(
                    buffer[(i, j)].to_bits(),
                    fresh[(i, j)].to_bits(),
                    "({i}, {j})"
                );
            }
        }
    }

    #[test]
    fn polynomial_names_follow_scikit_learn_order() {
        let library = FeatureLibrary::from_spec(&LibrarySpec::parse("poly:2").unwrap()).unwrap();
        assert_eq!(
            library.feature_names(&["x", "y"]),
            vec!["1", "x", "y", "x^2", "x*y", "y^2"]
        );
        let cubic = FeatureLibrary::from_spec(&LibrarySpec::Polynomial {
            degree: 3,
            constant: false,
        })
        .unwrap();
        let names = cubic.feature_names(&["x", "u"]);
        assert_eq!(names.len(), cubic.feature_count(2));
        assert!(names.contains(&"x^2*u".to_string()));
        assert_eq!(names[2..5], ["x^2", "x*u", "u^2"]);
    }

    #[test]
    fn fourier_names_and_values_follow_pysindy_order() {
        let library = FeatureLibrary::from_spec(&LibrarySpec::Fourier { frequencies: 2 }).unwrap();
        assert_eq!(
            library.feature_names(&["x", "u"]),
            vec![
                "sin(x)", "cos(x)", "sin(u)", "cos(u)", "sin(2*x)", "cos(2*x)", "sin(2*u)",
                "cos(2*u)"
            ]
        );
        let inputs = Mat::from_fn(2, 2, |i, j| 0.3 + i as f64 + 0.5 * j as f64);
        let theta = library.transform(inputs.as_ref());
        assert_eq!(theta[(1, 5)], (2.0f64 * 1.3).cos());
        assert_eq!(theta[(0, 2)], 0.8f64.sin());
        let mut row = Vec::new();
        library.transform_row(&[1.3, 1.8], &mut row);
        assert_eq!(row, (0..8).map(|j| theta[(1, j)]).collect::<Vec<_>>());
    }

    #[test]
    fn concatenation_and_custom_functions() {
        let spec = LibrarySpec::parse("poly:1:noconstant+fourier:1").unwrap();
        assert_eq!(spec.to_string(), "poly:1:noconstant+fourier:1");
        let library = FeatureLibrary::from_spec(&spec).unwrap().concat(
            FeatureLibrary::custom(vec![CustomFunction::new("exp({})", f64::exp).unwrap()])
                .unwrap(),
        );
        assert_eq!(
            library.feature_names(&["x"]),
            vec!["x", "sin(x)", "cos(x)", "exp(x)"]
        );
        assert!(library.spec().is_none());
        let theta = library.transform(Mat::from_fn(1, 1, |_, _| 2.0).as_ref());
        assert_eq!(theta[(0, 3)], 2.0f64.exp());
    }

    #[test]
    fn bad_specifications_are_rejected_with_the_text() {
        for text in [
            "poly",
            "poly:x",
            "spline:3",
            "fourier:0",
            "poly:0:noconstant",
        ] {
            let error = LibrarySpec::parse(text).unwrap_err().to_string();
            assert!(!error.contains('\n'), "{error}");
            assert!(error.contains("librar") || error.contains(text), "{error}");
        }
        assert!(CustomFunction::new("exp", f64::exp).is_err());
    }

    #[test]
    fn feature_counts_are_in_closed_form_and_agree_with_the_names() {
        for inputs in 0..5 {
            for degree in 0..5 {
                for constant in [true, false] {
                    let spec = LibrarySpec::Polynomial { degree, constant };
                    let library = FeatureLibrary {
                        parts: vec![Part::Polynomial { degree, constant }],
                    };
                    let count = monomials(inputs, degree, constant).len();
                    assert_eq!(spec.feature_count(inputs), Some(count));
                    assert_eq!(library.feature_count(inputs), count);
                }
            }
        }
        let spec = LibrarySpec::parse("poly:2:noconstant+fourier:3").unwrap();
        let library = FeatureLibrary::from_spec(&spec).unwrap();
        let names = library.feature_names(&["x", "y", "u"]);
        assert_eq!(spec.feature_count(3), Some(names.len()));
        assert_eq!(library.checked_feature_count(3).unwrap(), names.len());
        // C(503, 3) on three inputs, computed without enumerating 21 million monomials.
        let poly = LibrarySpec::Polynomial {
            degree: 500,
            constant: true,
        };
        assert_eq!(poly.feature_count(3), Some(21_084_251));
        assert_eq!(poly.feature_count(1), Some(501));
        let huge = LibrarySpec::Polynomial {
            degree: usize::MAX,
            constant: true,
        };
        assert_eq!(huge.feature_count(1), None);
        assert_eq!(huge.feature_count(0), Some(1));
        assert_eq!(
            LibrarySpec::Fourier {
                frequencies: usize::MAX
            }
            .feature_count(1),
            None
        );
    }

    #[test]
    fn libraries_larger_than_the_limit_are_refused_before_anything_is_enumerated() {
        // The spec alone: too many features on a single input.
        for text in [
            "fourier:1000000000",
            "fourier:5001",
            "poly:10000",
            "poly:1:noconstant+fourier:5000",
        ] {
            let message = LibrarySpec::parse(text).unwrap_err().to_string();
            assert!(
                message.contains(&format!("library '{text}'"))
                    && message.contains("limit of 10000")
                    && !message.contains('\n'),
                "{message}"
            );
        }
        assert!(
            FeatureLibrary::from_spec(&LibrarySpec::Polynomial {
                degree: usize::MAX,
                constant: false
            })
            .is_err()
        );
        LibrarySpec::parse("fourier:5000").unwrap();
        // On the actual inputs: poly:500 is 501 features on one input, 21 million on three (14 GB
        // of names and more of Θ): refused in closed form, in no time and memory.
        let library = FeatureLibrary::from_spec(&LibrarySpec::parse("poly:500").unwrap()).unwrap();
        let start = std::time::Instant::now();
        for error in [
            library.checked_feature_count(3).unwrap_err(),
            library.unique_feature_names(&["x", "y", "u"]).unwrap_err(),
        ] {
            let message = error.to_string();
            assert_eq!(
                message,
                "invalid library 'poly:500': 21084251 features on 3 inputs, more than the limit \
                 of 10000 (sindy::MAX_FEATURES)"
            );
        }
        assert!(start.elapsed().as_secs() < 1, "{:?}", start.elapsed());
        assert_eq!(library.checked_feature_count(1).unwrap(), 501);
        let custom =
            FeatureLibrary::custom(vec![CustomFunction::new("exp({})", f64::exp).unwrap()])
                .unwrap();
        assert!(custom.checked_feature_count(10_001).is_err());
        assert_eq!(custom.checked_feature_count(10_000).unwrap(), 10_000);
    }
}
