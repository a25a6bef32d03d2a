"""The Python reference of the ingestion bench (scripts/bench/threads.sh): the seconds pyarrow
takes to read the same columns of the same file, as a CSV (pyarrow.csv, multi-threaded) and as
Parquet (pyarrow.parquet), the fastest of three reads each. Prints one JSON object.

Usage: .venv/bin/python ingest_reference.py CSV PARQUET STATES CONTROLS
"""

import json
import sys
import time

import pyarrow.csv as csv
import pyarrow.parquet as parquet


def fastest(read, repeats=3):
    """The fastest of `repeats` calls of `read`, in seconds, and the rows it read."""
    best, rows = float("inf"), 0
    for _ in range(repeats):
        began = time.perf_counter()
        rows = read().num_rows
        best = min(best, time.perf_counter() - began)
    return best, rows


def main():
    csv_path, parquet_path = sys.argv[1], sys.argv[2]
    states, controls = int(sys.argv[3]), int(sys.argv[4])
    names = ["t"] + [f"x{i}" for i in range(states)] + [f"u{i}" for i in range(controls)]
    options = csv.ConvertOptions(include_columns=names)
    csv_seconds, rows = fastest(lambda: csv.read_csv(csv_path, convert_options=options))
    parquet_seconds, _ = fastest(lambda: parquet.read_table(parquet_path, columns=names))
    print(json.dumps({"rows": rows, "csv_seconds": csv_seconds, "parquet_seconds": parquet_seconds}))


if __name__ == "__main__":
    main()
