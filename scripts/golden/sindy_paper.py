"""PySINDy reference for the paper's SINDy columns (12 cells: 3 formulations x 4 wind conditions).

Protocol (issue 3): baseline figure-8 flights; support = rows [0, n/2), query = rows [n/2, n);
target = forward difference on each segment separately (last row backward); inputs X = [x, u] with
u = R[:, 2] * T_sp (translational), pwm/1000 (attitude), (pwm/1000)^2 (full); library = Fourier K = 1,
no constant; STLSQ threshold 0.2, alpha 0.05; MSE = mean over samples and output dimensions.

"tables" fits on the forward differences (the issue's protocol); "tables_central_fit" lets PySINDy
estimate the fit targets itself (its default FiniteDifference, order 2: central differences with
second-order one-sided ends) and still scores against forward differences. The second is much
closer to the published attitude and full columns.

Usage: .venv/bin/python scripts/golden/sindy_paper.py [DATA_DIR] > scripts/golden/sindy_paper.json
"""

import json
import os
import sys
import time

import numpy as np
import pandas as pd
import pysindy as ps

CONDITIONS = [("35wind", "35wind"), ("70p20sint", "70psin20"), ("70wind", "70wind"), ("100wind", "100wind")]
FORMULATIONS = ["translational", "attitude", "full"]


def parse_column(frame, name):
    return np.array([json.loads(cell) for cell in frame[name]], dtype=float)


def read_flight(path):
    frame = pd.read_csv(path)
    t = frame["t"].to_numpy(dtype=float)
    flight = {
        "dt": (t[-1] - t[0]) / (len(t) - 1),
        "v": parse_column(frame, "v"),
        "w": parse_column(frame, "w"),
        "R": parse_column(frame, "R").reshape(-1, 3, 3),
        "T_sp": parse_column(frame, "T_sp").reshape(-1),
        "pwm": parse_column(frame, "pwm"),
    }
    return flight


def formulation_data(flight, formulation):
    if formulation == "translational":
        return flight["v"], flight["R"][:, :, 2] * flight["T_sp"][:, None]
    if formulation == "attitude":
        return flight["w"], flight["pwm"] / 1000.0
    return np.hstack([flight["v"], flight["w"]]), (flight["pwm"] / 1000.0) ** 2


def forward_difference(x, dt):
    d = np.empty_like(x)
    d[:-1] = (x[1:] - x[:-1]) / dt
    d[-1] = (x[-1] - x[-2]) / dt
    return d


def make_model(threshold=0.2, alpha=0.05):
    return ps.SINDy(
        optimizer=ps.STLSQ(threshold=threshold, alpha=alpha),
        feature_library=ps.FourierLibrary(n_frequencies=1),
    )


def evaluate(flight, formulation, central_fit=False):
    x, u = formulation_data(flight, formulation)
    n = len(x)
    half = n // 2
    segments = [(x[:half], u[:half]), (x[half:], u[half:])]
    targets = [forward_difference(s, flight["dt"]) for s, _ in segments]
    model = make_model()
    if central_fit:
        model.fit(segments[0][0], t=flight["dt"], u=segments[0][1])
    else:
        model.fit(segments[0][0], t=flight["dt"], x_dot=targets[0], u=segments[0][1])
    mses = []
    for (xs, us), target in zip(segments, targets):
        prediction = model.predict(xs, u=us)
        mses.append(float(np.mean((prediction - target) ** 2)))
    return {
        "adapt": mses[0],
        "gen": mses[1],
        "features": model.get_feature_names(),
        "coefficients": model.coefficients().tolist(),
    }


def main():
    data_dir = sys.argv[1] if len(sys.argv) > 1 else os.environ.get("NEURAL_FLY_DIR", "data/neural-fly")
    start = time.perf_counter()
    tables = {f: {} for f in FORMULATIONS}
    central = {f: {} for f in FORMULATIONS}
    for condition, label in CONDITIONS:
        flight = read_flight(os.path.join(data_dir, "experiment", f"custom_figure8_baseline_{condition}.csv"))
        for formulation in FORMULATIONS:
            tables[formulation][label] = evaluate(flight, formulation)
            central[formulation][label] = evaluate(flight, formulation, central_fit=True)
    elapsed = time.perf_counter() - start
    print(json.dumps({
        "generator": "scripts/golden/sindy_paper.py",
        "pysindy": ps.__version__ if hasattr(ps, "__version__") else "unknown",
        "numpy": np.__version__,
        "seconds": elapsed,
        "tables": tables,
        "tables_central_fit": central,
    }, indent=1))


if __name__ == "__main__":
    main()
