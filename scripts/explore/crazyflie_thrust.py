"""Exploration (not part of `make`): what the Crazyflie log's own accelerometer says of its thrust,
independently of the mismatch tool. The log (data/crazyflie/randomwalk_l_cf102_01.csv) holds the
acceleration (world, z up, gravity included), the attitude, the four PWM commands and the battery
voltage; the thrust map is the README's (neural-swarm's parrot-frame polynomial in PWM and Vbat/4.2,
grams per motor), the mass 67 g.

Prints
1. the measured thrust (m times the specific force along the body z axis) over the map's, median per
   4 cm of height and per sixth of the flight above 0.2 m: a thrust deficit would read below 1;
2. the correlation of the two thrusts' fast parts (each minus its ±0.5 s moving mean) against the
   delay of the measured one, in rows of about 10 ms: where it peaks is how late the measured
   thrust follows the commanded one.

usage: python3 scripts/explore/crazyflie_thrust.py [CSV]   (standard library only)
"""

import csv
import math
import statistics
import sys

MASS_KG = 0.067
G = 9.81
# f[g] = C00 + C10 p + C01 v + C20 p² + C11 v p, p the PWM fraction, v = Vbat / 4.2.
C00, C10, C01, C20, C11 = (
    44.10386631845999,
    -122.51151800146272,
    -36.18484254283743,
    53.10772568607133,
    107.6819263349139,
)


def map_thrust_n(row):
    v = row["Vbat[V]"] / 4.2
    grams = 0.0
    for i in range(1, 5):
        p = row[f"u{i}[PWM]"]
        grams += C00 + C10 * p + C01 * v + C20 * p * p + C11 * v * p
    return grams * G / 1000.0


def measured_thrust_n(row):
    qx, qy, qz, qw = row["qx"], row["qy"], row["qz"], row["qw"]
    body_z = (2 * (qx * qz + qw * qy), 2 * (qy * qz - qw * qx), 1 - 2 * (qx * qx + qy * qy))
    a = (row["ax[m/s^2]"], row["ay[m/s^2]"], row["az[m/s^2]"])
    return MASS_KG * sum(a[i] * body_z[i] for i in range(3))


def fast_part(values, half=50):
    out = []
    for i in range(len(values)):
        window = values[max(0, i - half) : i + half + 1]
        out.append(values[i] - sum(window) / len(window))
    return out


def main():
    path = sys.argv[1] if len(sys.argv) > 1 else "data/crazyflie/randomwalk_l_cf102_01.csv"
    with open(path) as f:
        f.read(2)  # the header is written as a comment, "# "
        rows = [{k: float(v) for k, v in row.items()} for row in csv.DictReader(f)]
    measured = [measured_thrust_n(r) for r in rows]
    mapped = [map_thrust_n(r) for r in rows]
    ratio = [m / p for m, p in zip(measured, mapped)]

    print("measured / map thrust, median per height (m):")
    bins = {}
    for r, x in zip(rows, ratio):
        bins.setdefault(round(r["z[m]"] / 0.04) * 0.04, []).append(x)
    for height in sorted(bins):
        if len(bins[height]) >= 50:
            print(f"  z ~ {height:.2f}: {statistics.median(bins[height]):.3f} ({len(bins[height])} rows)")

    print("measured / map thrust above 0.2 m, median per sixth of the flight:")
    n = len(rows)
    for part in range(6):
        span = range(part * n // 6, (part + 1) * n // 6)
        high = [ratio[k] for k in span if rows[k]["z[m]"] > 0.2]
        volts = statistics.median(rows[k]["Vbat[V]"] for k in span)
        print(f"  {part + 1}: {statistics.median(high):.3f} ({len(high)} rows, Vbat {volts:.2f} V)")

    fast_measured, fast_mapped = fast_part(measured), fast_part(mapped)
    inner = range(60, n - 60)
    print("correlation of the fast parts against the measured thrust's delay (rows):")
    best = (0, -1.0)
    for lag in range(0, 41, 2):
        num = sum(fast_mapped[k] * fast_measured[k + lag] for k in inner if k + lag < n)
        den = math.sqrt(
            sum(fast_mapped[k] ** 2 for k in inner if k + lag < n)
            * sum(fast_measured[k + lag] ** 2 for k in inner if k + lag < n)
        )
        best = max(best, (lag, num / den), key=lambda b: b[1])
        print(f"  {lag:2d}: {num / den:.3f}")
    steps = [rows[k + 1]["time[ms]"] - rows[k]["time[ms]"] for k in range(n - 1)]
    print(f"peak at {best[0]} rows ({best[0] * statistics.median(steps) * 1e-3:.0f} ms), correlation {best[1]:.3f}")


if __name__ == "__main__":
    main()
