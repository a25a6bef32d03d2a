"""Exploration (not part of `make`): does the way the support segment is cross-validated decide
which library wins? A NumPy re-implementation of `lag-ridge-cv` (the same as
scripts/explore/position_features.py, whose helpers it imports) with three candidates per cell:

- base:    the lag-ridge-cv library fitted on forward differences (the headline variant);
- +pos:    the same plus the three position coordinates as linear features;
- central: the base library fitted on central differences of the support segment (scored, like
           everything here, against forward differences).

Each candidate's ridge penalty and its cross-validation score come from one of two schemes inside
the support half: `blocked` 5-fold (the project's scheme: every block held out once, the model fitted
on the four others, past and future) and `forward` chaining (block k scored by a model fitted on
blocks 0..k-1 only, as the query segment is scored by a model fitted on its past). Prints the query
MSE of every candidate (penalty by blocked CV) and, per scheme, the candidate it picks with the query
MSE of that candidate under the penalty the same scheme chose.

Outcome (run on the shared flights): blocked CV picks base in 9 of 12 cells and +pos in 3, its picks
lying within 0.01 of the best candidate's query MSE in every cell but two: translational 70wind (base
0.178 where +pos gives 0.166 and central 0.171) and attitude 70wind (base 0.570, +pos 0.558).
Forward chaining picks worse than blocked CV in 11 of 12 cells, by a wide margin in most
(translational 70wind 0.279, attitude 70wind 0.824, full 70wind 0.549; better only in translational
35wind, 0.179 against 0.183): its early blocks fit on a few hundred samples, so it chooses penalties
for a much smaller data set than the final fit has. The candidates +pos and central were assembled
after earlier explorations had shown their query errors; nothing here is used by the project, and
blocked CV stays.

usage: .venv/bin/python scripts/explore/selection_scheme.py [DATA_DIR]
"""

import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import position_features as pf  # noqa: E402

CANDIDATES = ("base", "+pos", "central")
SCHEMES = ("blocked", "forward")


def central_difference(x, dt):
    d = np.empty_like(x)
    d[1:-1] = (x[2:] - x[:-2]) / (2 * dt)
    d[0] = (x[1] - x[0]) / dt
    d[-1] = (x[-1] - x[-2]) / dt
    return d


def cross_validated(a, y_fit, y_score, scheme):
    """Ridge with the penalty of lowest CV error under `scheme`; returns (model, CV error)."""
    n = len(a)
    folds = np.array_split(np.arange(n), 5)
    best = None
    for lam in pf.LAMBDAS:
        errors = []
        for k, fold in enumerate(folds):
            if scheme == "blocked":
                train = np.setdiff1d(np.arange(n), fold)
            elif k == 0:
                continue
            else:
                train = np.arange(fold[0])
            model = pf.ridge(a[train], y_fit[train], lam)
            errors.append(((model(a[fold]) - y_score[fold]) ** 2).mean())
        error = float(np.mean(errors))
        if best is None or error < best[0]:
            best = (error, lam)
    return pf.ridge(a, y_fit, best[1]), best[0]


def main():
    data_dir = sys.argv[1] if len(sys.argv) > 1 else os.environ.get("NEURAL_FLY_DIR", "data/neural-fly")
    header = "".join(f"{c:>10}" for c in CANDIDATES)
    print(f"{'formulation':14}{'condition':11}{header}   blocked pick       forward pick")
    for name, (states, control) in pf.FORMULATIONS.items():
        for condition in pf.CONDITIONS:
            d = pf.load(os.path.join(data_dir, "experiment", f"custom_figure8_baseline_{condition}.csv"))
            n, dt = len(d["t"]), d["t"][1] - d["t"][0]
            x, u, p = np.hstack([d[k] for k in states]), d[control], d["p"]
            support, query = slice(0, n // 2), slice(n // 2, n)
            target_support = pf.forward_difference(x[support], dt)
            target_query = pf.forward_difference(x[query], dt)
            setups = {}
            for candidate in CANDIDATES:
                with_position = candidate == "+pos"
                fit = central_difference(x[support], dt) if candidate == "central" else target_support
                setups[candidate] = (
                    pf.features(x[support], u[support], p[support], with_position),
                    pf.features(x[query], u[query], p[query], with_position),
                    fit,
                )
            query_mse = {scheme: {} for scheme in SCHEMES}
            cv = {scheme: {} for scheme in SCHEMES}
            for candidate, (a_support, a_query, fit) in setups.items():
                for scheme in SCHEMES:
                    gen = error = 0.0
                    for j in range(x.shape[1]):
                        model, cv_error = cross_validated(a_support, fit[:, [j]], target_support[:, [j]], scheme)
                        error += cv_error / x.shape[1]
                        gen += ((model(a_query) - target_query[:, [j]]) ** 2).mean() / x.shape[1]
                    cv[scheme][candidate] = error
                    query_mse[scheme][candidate] = gen
            picks = {scheme: min(CANDIDATES, key=lambda c: cv[scheme][c]) for scheme in SCHEMES}
            row = "".join(f"{query_mse['blocked'][c]:10.4f}" for c in CANDIDATES)
            chosen = "".join(f"   {picks[s]:8} {query_mse[s][picks[s]]:.4f}" for s in SCHEMES)
            print(f"{name:14}{condition:11}{row}{chosen}", flush=True)


if __name__ == "__main__":
    main()
