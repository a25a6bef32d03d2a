"""Exploration (not part of `make`): does adding the position p to the lag-ridge-cv library lower
the error? A NumPy re-implementation of `lag-ridge-cv` (linear + sin/cos of X = [x, u], first-order
control lags with poles 0.5 / 0.8 / 0.95, standardised ridge with intercept, λ per output by blocked
5-fold CV on the support half), with and without the three position coordinates as extra linear
features. It reproduces the Rust variant's translational numbers (0.1825 / 0.1006 / 0.1781 /
0.1952). Prints, per cell, the query MSE and the support CV MSE of both libraries.

The point of the printout is the comparison of the two columns: the query error (which must not
choose anything) and the support cross-validation (which may). See the closing note of issue 7.

usage: .venv/bin/python scripts/explore/position_features.py [DATA_DIR]
"""

import csv
import json
import os
import sys

import numpy as np

LAMBDAS = (0.0, 1e-6, 1e-5, 1e-4, 1e-3, 1e-2, 1e-1, 1.0)
POLES = (0.5, 0.8, 0.95)
CONDITIONS = ("35wind", "70p20sint", "70wind", "100wind")
FORMULATIONS = {"translational": (["v"], "u_thrust"), "attitude": (["w"], "n"), "full": (["v", "w"], "n_squared")}


def load(path):
    rows = list(csv.DictReader(open(path)))
    column = lambda k: np.array([json.loads(r[k]) for r in rows], dtype=float)  # noqa: E731
    thrust = column("T_sp").reshape(len(rows), -1)[:, 0]
    rotation = column("R")
    pwm = column("pwm") / 1000.0
    return {
        "t": np.array([float(r["t"]) for r in rows]),
        "p": column("p"),
        "v": column("v"),
        "w": column("w"),
        "u_thrust": rotation[:, :, 2] * thrust[:, None],
        "n": pwm,
        "n_squared": pwm**2,
    }


def forward_difference(x, dt):
    d = np.empty_like(x)
    d[:-1] = (x[1:] - x[:-1]) / dt
    d[-1] = d[-2]
    return d


def lag(u, pole):
    out, state = np.empty_like(u), u[0].copy()
    for k in range(len(u)):
        state = pole * state + (1 - pole) * u[k]
        out[k] = state
    return out


def features(x, u, p, with_position):
    inputs = np.hstack([x, u])
    columns = [inputs, np.sin(inputs), np.cos(inputs)] + [lag(u, a) for a in POLES]
    if with_position:
        columns.append(p)
    return np.hstack(columns)


def ridge(a, y, lam):
    mean, std = a.mean(0), a.std(0)
    std[std == 0] = 1
    z = (a - mean) / std
    y_mean = y.mean(0)
    w = np.linalg.solve(z.T @ z + lam * len(z) * np.eye(z.shape[1]), z.T @ (y - y_mean))
    return lambda b: ((b - mean) / std) @ w + y_mean


def cross_validated(a, y):
    folds = np.array_split(np.arange(len(a)), 5)
    best = None
    for lam in LAMBDAS:
        error = 0.0
        for fold in folds:
            train = np.setdiff1d(np.arange(len(a)), fold)
            error += ((ridge(a[train], y[train], lam)(a[fold]) - y[fold]) ** 2).mean() / len(folds)
        if best is None or error < best[0]:
            best = (error, lam)
    return ridge(a, y, best[1]), best[0]


def main():
    data_dir = sys.argv[1] if len(sys.argv) > 1 else os.environ.get("NEURAL_FLY_DIR", "data/neural-fly")
    print(f"{'formulation':14}{'condition':11}{'query lag':>10}{'query +p':>10}{'CV lag':>9}{'CV +p':>9}")
    for name, (states, control) in FORMULATIONS.items():
        for condition in CONDITIONS:
            d = load(os.path.join(data_dir, "experiment", f"custom_figure8_baseline_{condition}.csv"))
            n, dt = len(d["t"]), d["t"][1] - d["t"][0]
            x, u, p = np.hstack([d[k] for k in states]), d[control], d["p"]
            support, query = slice(0, n // 2), slice(n // 2, n)
            target_support = forward_difference(x[support], dt)
            target_query = forward_difference(x[query], dt)
            scores = []
            for with_position in (False, True):
                a_support = features(x[support], u[support], p[support], with_position)
                a_query = features(x[query], u[query], p[query], with_position)
                gen = cv = 0.0
                for j in range(x.shape[1]):
                    model, cv_error = cross_validated(a_support, target_support[:, [j]])
                    gen += ((model(a_query) - target_query[:, [j]]) ** 2).mean() / x.shape[1]
                    cv += cv_error / x.shape[1]
                scores.append((gen, cv))
            print(f"{name:14}{condition:11}{scores[0][0]:10.4f}{scores[1][0]:10.4f}{scores[0][1]:9.4f}{scores[1][1]:9.4f}")


if __name__ == "__main__":
    main()
