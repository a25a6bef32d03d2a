"""The arithmetic floor of a large SINDy fit (scripts/bench/threads.sh): the seconds OpenBLAS (NumPy)
takes to form the Gram matrix ΘᵀΘ of the cubic library of a CSV written by scaling_data.py, summed
over blocks of rows (the library's evaluation and the reading are not timed). Prints one JSON object:
the Gram seconds, the rows and the features.

Usage: .venv/bin/python gram_floor.py CSV STATES CONTROLS
"""

import itertools
import json
import sys
import time

import numpy as np
import pandas as pd

BLOCK_ROWS = 65536


def cubic_library(inputs):
    """1, every input, every product of two and of three (with repeats): PySINDy's order."""
    columns = inputs.shape[1]
    terms = [np.ones(len(inputs))]
    for degree in (1, 2, 3):
        for combination in itertools.combinations_with_replacement(range(columns), degree):
            terms.append(np.prod(inputs[:, combination], axis=1))
    return np.column_stack(terms)


def main():
    path, states, controls = sys.argv[1], int(sys.argv[2]), int(sys.argv[3])
    names = [f"x{i}" for i in range(states)] + [f"u{i}" for i in range(controls)]
    inputs = pd.read_csv(path, usecols=names)[names].to_numpy()
    features = cubic_library(inputs[:2]).shape[1]
    gram = np.zeros((features, features))
    seconds = 0.0
    for start in range(0, len(inputs), BLOCK_ROWS):
        theta = cubic_library(inputs[start:start + BLOCK_ROWS])
        began = time.perf_counter()
        # theta.T @ theta is recognised by NumPy as a symmetric rank-k update (syrk).
        gram += theta.T @ theta
        seconds += time.perf_counter() - began
    print(json.dumps({"seconds": seconds, "rows": len(inputs), "features": features}))


if __name__ == "__main__":
    main()
