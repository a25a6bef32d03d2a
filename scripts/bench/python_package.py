"""`make bench`, Python package part (scripts/bench/python_package.sh): learn-sysid against PySINDy
from Python, in one process on this machine.

- one support segment: the paper's SINDy fit of the full formulation on the support half of the
  35wind baseline flight (FourierLibrary K=1 on [x, u], STLSQ threshold 0.2, alpha 0.05, forward
  differences given), median of 31 fits: PySINDy, learn_sysid.SINDy, and PySINDy with
  learn_sysid.STLSQ as its optimizer (PySINDy builds the library, Rust regresses);
- 100,000 rows × 455 features: SINDy(PolynomialLibrary(3), STLSQ(0.1)).fit(x, t=t, u=u) on the
  scaling bench's recording (scripts/bench/scaling_data.py, 10 states and 2 controls), made in
  memory; learn_sysid once each of 3 runs (the fastest kept), PySINDy once;
- the call overhead: learn_sysid.SINDy.fit against the extension's fit called directly with the
  same arrays, and a fit of 50 rows (what a call costs when the work is nothing).

The coefficients of each pair are compared. Prints one JSON object.
Usage: PYTHONPATH=target/python .venv/bin/python scripts/bench/python_package.py [DATA_DIR]
"""

import json
import os
import sys
import time
import warnings

HERE = os.path.dirname(__file__)
sys.path.insert(0, os.path.join(HERE, "..", "golden"))
sys.path.insert(0, HERE)

import numpy as np  # noqa: E402
import pysindy as ps  # noqa: E402

import learn_sysid as ls  # noqa: E402
from learn_sysid import _native  # noqa: E402
import scaling_data  # noqa: E402
import sindy_paper as paper  # noqa: E402


def seconds(runs, work, pick=np.median):
    times = []
    for _ in range(runs):
        start = time.perf_counter()
        work()
        times.append(time.perf_counter() - start)
    return float(pick(times))


def support_segment(data_dir):
    flight = paper.read_flight(os.path.join(data_dir, "experiment", "custom_figure8_baseline_35wind.csv"))
    x, u = paper.formulation_data(flight, "full")
    half = len(x) // 2
    xs, us = np.ascontiguousarray(x[:half]), np.ascontiguousarray(u[:half])
    target = paper.forward_difference(xs, flight["dt"])
    dt = flight["dt"]
    pysindy = lambda: paper.make_model().fit(xs, t=dt, x_dot=target, u=us)
    ours = lambda: ls.SINDy(optimizer=ls.STLSQ(0.2, 0.05), feature_library=ls.FourierLibrary(1)).fit(
        xs, t=dt, x_dot=target, u=us)
    hosted = lambda: ps.SINDy(optimizer=ls.STLSQ(0.2, 0.05), feature_library=ps.FourierLibrary(1)).fit(
        xs, t=dt, x_dot=target, u=us)
    reference = pysindy().coefficients()
    difference = max(float(np.max(np.abs(f().coefficients() - reference))) for f in (ours, hosted))
    return {
        "rows": int(half),
        "features": int(reference.shape[1]),
        "pysindy_s": seconds(31, pysindy),
        "learn_sysid_s": seconds(31, ours),
        "pysindy_hosting_our_stlsq_s": seconds(31, hosted),
        "largest_coefficient_difference": difference,
    }


def large(rows):
    t = np.arange(rows) * 1e-3
    values = scaling_data.Recording(10, 2).values(t)
    x, u = np.ascontiguousarray(values[:, :10]), np.ascontiguousarray(values[:, 10:])
    make = lambda: ls.SINDy(optimizer=ls.STLSQ(0.1), feature_library=ls.PolynomialLibrary(3))
    ours_s = seconds(3, lambda: make().fit(x, t=t, u=u), pick=min)
    model = make().fit(x, t=t, u=u)
    names = [f"x{i}" for i in range(10)], [f"u{i}" for i in range(2)]
    arrays = [(t, x, u, None)]
    specs = (ls.PolynomialLibrary(3)._spec(), ls.STLSQ(0.1)._spec(), ls.FiniteDifference()._spec())
    native_s = seconds(3, lambda: _native.fit_sindy(arrays, *names, *specs), pick=min)
    start = time.perf_counter()
    reference = ps.SINDy(feature_library=ps.PolynomialLibrary(degree=3), optimizer=ps.STLSQ(threshold=0.1))
    reference.fit(x, t=t, u=u)
    pysindy_s = time.perf_counter() - start
    difference = float(np.max(np.abs(model.coefficients() - reference.coefficients())))
    return {
        "rows": rows,
        "features": int(model.coefficients().shape[1]),
        "pysindy_s": pysindy_s,
        "learn_sysid_s": ours_s,
        "extension_call_s": native_s,
        "largest_coefficient_difference": difference,
        "largest_coefficient": float(np.max(np.abs(reference.coefficients()))),
    }


def tiny_call():
    t = np.arange(50) * 0.01
    x = np.exp(-0.5 * t)[:, None]
    return seconds(201, lambda: ls.SINDy().fit(x, t=t))


def main():
    data_dir = sys.argv[1] if len(sys.argv) > 1 else os.environ.get("NEURAL_FLY_DIR", "data/neural-fly")
    warnings.simplefilter("ignore")
    rows = int(os.environ.get("PYTHON_BENCH_ROWS", "100000"))
    print(json.dumps({"support": support_segment(data_dir), "large": large(rows), "tiny_fit_s": tiny_call()}))


if __name__ == "__main__":
    main()
