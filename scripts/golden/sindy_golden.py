"""Golden values for the sindy crate's optimizers, computed with PySINDy (STLSQ) and scikit-learn
(LASSO) on a fixed library matrix that this script builds deterministically (no random numbers).

Usage: .venv/bin/python scripts/golden/sindy_golden.py > scripts/golden/sindy_golden.json
"""

import json
import warnings

import numpy as np
import pysindy as ps
import sklearn
from sklearn.linear_model import Lasso

N_SAMPLES, N_FEATURES = 150, 7


def library_matrix():
    k = np.arange(N_SAMPLES)[:, None]
    j = np.arange(N_FEATURES)[None, :]
    # smooth, correlated, full-rank columns of different scales
    return np.sin(0.37 * (k + 1) * (j + 1) + 0.11 * j) * (1.0 + 0.3 * j) + 0.2 * np.cos(0.05 * k * (j + 2))


def targets(theta):
    true = np.array([
        [1.5, 0.0, -0.8, 0.0, 0.0, 0.12, 0.0],
        [0.0, 2.0, 0.0, 0.0, -0.25, 0.0, 0.05],
        [0.3, -0.3, 0.3, -0.3, 0.3, -0.3, 0.3],
    ])
    k = np.arange(N_SAMPLES)[:, None]
    disturbance = 0.05 * np.sin(1.7 * k + np.arange(3)[None, :]) * np.cos(0.21 * k)
    return theta @ true.T + disturbance


def main():
    theta = library_matrix()
    y = targets(theta)
    stlsq_cases = []
    for threshold, alpha, max_iter in [(0.1, 0.05, 20), (0.2, 0.05, 20), (0.28, 0.5, 20), (0.35, 0.0, 20), (0.1, 5.0, 2), (0.0, 0.05, 20)]:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            opt = ps.STLSQ(threshold=threshold, alpha=alpha, max_iter=max_iter)
            opt.fit(theta, y)
        stlsq_cases.append({
            "threshold": threshold,
            "alpha": alpha,
            "max_iter": max_iter,
            "iterations": len(opt.history_) - 1,
            "coefficients": opt.coef_.tolist(),
        })
    lasso_cases = []
    for lam in [0.5, 2.0, 10.0]:
        # scikit-learn minimises 1/(2n)||y - X w||^2 + a ||w||_1, so a = lambda / n.
        model = Lasso(alpha=lam / N_SAMPLES, fit_intercept=False, tol=1e-14, max_iter=1_000_000)
        model.fit(theta, y)
        lasso_cases.append({"lambda": lam, "coefficients": model.coef_.tolist()})
    print(json.dumps({
        "generator": "scripts/golden/sindy_golden.py",
        "pysindy": ps.__version__ if hasattr(ps, "__version__") else "unknown",
        "sklearn": sklearn.__version__,
        "library": theta.tolist(),
        "targets": y.tolist(),
        "stlsq": stlsq_cases,
        "lasso": lasso_cases,
    }))


if __name__ == "__main__":
    main()
