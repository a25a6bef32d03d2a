"""Reference solutions of three small nonlinear least-squares problems, computed with SciPy's
`scipy.optimize.least_squares` (trust-region reflective, analytic Jacobians, tolerances near machine
precision), for the golden tests of the mismatch crate's solver (`crates/mismatch/src/least_squares.rs`,
which hard-codes the printed values).

Problems (the same residuals are written in the Rust tests):
- exponential decay with a bound active at the solution: y = a·exp(−b·t) + c fitted to
  2·exp(−0.7·t) + 0.3 + 0.05·sin(3·t) on t = 0, 0.5, …, 10, with c ≥ 0.5 (the data want c ≈ 0.3);
- Rosenbrock's residual (10·(x₂ − x₁²), 1 − x₁) with x₂ ≥ 1.5 (SciPy's documented example);
- Kowalik and Osborne's enzyme reaction (Moré, Garbow and Hillstrom's problem 15), unbounded.

Usage (numpy and scipy in a git-ignored environment, the versions `scripts/python-env.sh` pins):
    python3 -m venv scripts/.venv
    scripts/.venv/bin/pip install numpy==2.4.6 scipy==1.17.1
    scripts/.venv/bin/python scripts/golden/least_squares.py
"""

import json

import numpy as np
import scipy
from scipy.optimize import least_squares

TIMES = 0.5 * np.arange(21)
DECAY = 2.0 * np.exp(-0.7 * TIMES) + 0.3 + 0.05 * np.sin(3.0 * TIMES)


def decay_residual(x):
    a, b, c = x
    return a * np.exp(-b * TIMES) + c - DECAY


def decay_jacobian(x):
    a, b, _ = x
    e = np.exp(-b * TIMES)
    return np.column_stack([e, -a * TIMES * e, np.ones_like(TIMES)])


def rosenbrock_residual(x):
    return np.array([10.0 * (x[1] - x[0] ** 2), 1.0 - x[0]])


def rosenbrock_jacobian(x):
    return np.array([[-20.0 * x[0], 10.0], [-1.0, 0.0]])


KOWALIK_U = np.array([4.0, 2.0, 1.0, 0.5, 0.25, 0.167, 0.125, 0.1, 0.0833, 0.0714, 0.0625])
KOWALIK_Y = np.array(
    [0.1957, 0.1947, 0.1735, 0.16, 0.0844, 0.0627, 0.0456, 0.0342, 0.0323, 0.0235, 0.0246]
)


def kowalik_residual(x):
    u = KOWALIK_U
    return x[0] * (u * u + x[1] * u) / (u * u + x[2] * u + x[3]) - KOWALIK_Y


def kowalik_jacobian(x):
    u = KOWALIK_U
    denominator = u * u + x[2] * u + x[3]
    numerator = u * u + x[1] * u
    return np.column_stack(
        [
            numerator / denominator,
            x[0] * u / denominator,
            -x[0] * numerator * u / denominator**2,
            -x[0] * numerator / denominator**2,
        ]
    )


PROBLEMS = [
    ("decay", decay_residual, decay_jacobian, [1.0, 1.0, 1.0], ([0.0, 0.0, 0.5], [10.0, 5.0, 2.0])),
    ("rosenbrock", rosenbrock_residual, rosenbrock_jacobian, [2.0, 2.0], ([-np.inf, 1.5], np.inf)),
    ("kowalik", kowalik_residual, kowalik_jacobian, [0.25, 0.39, 0.415, 0.39], (-np.inf, np.inf)),
]


def main():
    solutions = {"scipy": scipy.__version__, "numpy": np.__version__}
    for name, residual, jacobian, start, bounds in PROBLEMS:
        fit = least_squares(
            residual, start, jac=jacobian, bounds=bounds, method="trf", ftol=1e-15, xtol=1e-15, gtol=1e-15
        )
        assert fit.success, (name, fit.message)
        solutions[name] = {
            "x": [float(v) for v in fit.x],
            # SciPy's cost is half the sum of squares.
            "sum_of_squares": float(2.0 * fit.cost),
            "active_mask": [int(v) for v in fit.active_mask],
            "message": fit.message,
        }
    print(json.dumps(solutions, indent=1))


if __name__ == "__main__":
    main()
