"""PySINDy side of the SINDy scaling bench (scripts/bench/scaling.sh): fits
`SINDy(PolynomialLibrary(3), STLSQ(0.1)).fit(x, t=t, u=u)` on a CSV written by scaling_data.py and
prints one JSON object: the fit's seconds (reading the CSV excluded) and the process's peak RSS.

Usage: .venv/bin/python sindy_scaling.py CSV STATES CONTROLS
"""

import json
import resource
import sys
import time
import warnings

import numpy as np
import pandas as pd
import pysindy as ps


def main():
    path, states, controls = sys.argv[1], int(sys.argv[2]), int(sys.argv[3])
    frame = pd.read_csv(path)
    t = frame["t"].to_numpy()
    x = frame[[f"x{i}" for i in range(states)]].to_numpy()
    u = frame[[f"u{i}" for i in range(controls)]].to_numpy()
    del frame
    warnings.filterwarnings("ignore")
    start = time.perf_counter()
    model = ps.SINDy(feature_library=ps.PolynomialLibrary(degree=3), optimizer=ps.STLSQ(threshold=0.1))
    model.fit(x, t=t, u=u)
    seconds = time.perf_counter() - start
    peak_kib = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    print(json.dumps({"seconds": seconds, "peak_rss_mb": peak_kib / 1024,
                      "features": len(model.get_feature_names())}))


if __name__ == "__main__":
    main()
