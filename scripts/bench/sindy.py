"""PySINDy side of `make bench` (see scripts/bench/sindy.sh): times the paper's SINDy protocol.

- one fit (FourierLibrary K=1 on [x, u], STLSQ threshold 0.2, alpha 0.05) of each formulation on
  the support half of the 35wind baseline flight, median of repeated fits;
- the whole 12-cell table including reading and parsing the four CSV files, median of 3 runs.

Prints one JSON object. Usage: .venv/bin/python scripts/bench/sindy.py [DATA_DIR]
"""

import json
import os
import sys
import time
import warnings

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "golden"))

import numpy as np  # noqa: E402
import threadpoolctl  # noqa: E402

import sindy_paper as paper  # noqa: E402


def median_seconds(runs, work):
    times = []
    for _ in range(runs):
        start = time.perf_counter()
        work()
        times.append(time.perf_counter() - start)
    return float(np.median(times))


def whole_table(data_dir):
    for condition, _ in paper.CONDITIONS:
        path = os.path.join(data_dir, "experiment", f"custom_figure8_baseline_{condition}.csv")
        flight = paper.read_flight(path)
        for formulation in paper.FORMULATIONS:
            paper.evaluate(flight, formulation)


def main():
    data_dir = sys.argv[1] if len(sys.argv) > 1 else os.environ.get("NEURAL_FLY_DIR", "data/neural-fly")
    warnings.simplefilter("ignore")
    flight = paper.read_flight(os.path.join(data_dir, "experiment", "custom_figure8_baseline_35wind.csv"))
    fits = {}
    for formulation in paper.FORMULATIONS:
        x, u = paper.formulation_data(flight, formulation)
        half = len(x) // 2
        xs, us = x[:half], u[:half]
        target = paper.forward_difference(xs, flight["dt"])

        def fit():
            paper.make_model().fit(xs, t=flight["dt"], x_dot=target, u=us)

        fits[formulation] = median_seconds(31, fit)
    table = median_seconds(3, lambda: whole_table(data_dir))
    blas = threadpoolctl.threadpool_info()
    print(json.dumps({
        "fit": fits,
        "table": table,
        "blas": [f"{b.get('internal_api')} {b.get('architecture')} x{b.get('num_threads')}" for b in blas],
    }))


if __name__ == "__main__":
    main()
