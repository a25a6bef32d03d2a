"""Writes a synthetic recording for the SINDy scaling bench: ROWS rows of a time column `t`
(1 ms steps), STATES smooth states `x0..` and CONTROLS controls `u0..`, each a sum of sinusoids
with random frequencies (0.05–3 Hz), amplitudes and phases, plus a random offset, so that the
cubic library is well conditioned. Deterministic (seed 7). Rows are written in chunks, so any
number of rows fits in memory.

Usage: python scaling_data.py ROWS OUT.csv [STATES [CONTROLS]]
"""

import sys

import numpy as np


class Recording:
    """The recording's generator: `values(t)` gives the STATES + CONTROLS columns at times t."""

    def __init__(self, states=10, controls=2):
        columns = states + controls
        rng = np.random.default_rng(7)
        self.frequencies = rng.uniform(0.05, 3.0, (columns, 4))
        self.amplitudes = rng.uniform(0.2, 1.0, (columns, 4))
        self.phases = rng.uniform(0.0, 2 * np.pi, (columns, 4))
        self.offsets = rng.uniform(-0.5, 0.5, columns)

    def values(self, t):
        angle = 2 * np.pi * self.frequencies[None, :, :] * t[:, None, None] + self.phases[None]
        return self.offsets + (self.amplitudes[None] * np.sin(angle)).sum(axis=2)


def main():
    rows, out = int(sys.argv[1]), sys.argv[2]
    states = int(sys.argv[3]) if len(sys.argv) > 3 else 10
    controls = int(sys.argv[4]) if len(sys.argv) > 4 else 2
    recording = Recording(states, controls)
    header = ["t"] + [f"x{i}" for i in range(states)] + [f"u{i}" for i in range(controls)]
    with open(out, "w") as fh:
        fh.write(",".join(header) + "\n")
        chunk = 200_000
        for start in range(0, rows, chunk):
            t = np.arange(start, min(rows, start + chunk)) * 1e-3
            np.savetxt(fh, np.column_stack([t, recording.values(t)]), delimiter=",", fmt="%.12g")


if __name__ == "__main__":
    main()
