#!/usr/bin/env bash
# `make bench`, SINDy part: Rust (dev profile, numeric crates optimised) against PySINDy on the
# paper's SINDy protocol, in one run on this machine. Needs the flight data (`make data`) and the
# Python environment (created here by scripts/python-env.sh if missing).
set -euo pipefail
cd "$(dirname "$0")/../.."

[ -x .venv/bin/python ] || scripts/python-env.sh
data_dir="${NEURAL_FLY_DIR:-data/neural-fly}"

rust_output=$(cargo bench --quiet --profile dev -p evaluation --bench sindy_paper 2>/dev/null)
echo "$rust_output" | grep -v '^BENCH_JSON'
rust_json=$(echo "$rust_output" | sed -n 's/^BENCH_JSON //p')
# OPENBLAS_CORETYPE / OPENBLAS_L2_SIZE slow a current numpy down: unset for the comparison only.
python_json=$(env -u OPENBLAS_CORETYPE -u OPENBLAS_L2_SIZE .venv/bin/python scripts/bench/sindy.py "$data_dir")

RUST="$rust_json" PYTHON="$python_json" python3 - <<'PY'
import json, os
rust, py = json.loads(os.environ["RUST"]), json.loads(os.environ["PYTHON"])
print(f"PySINDy BLAS: {', '.join(py['blas'])}; Rust threads: {rust['threads']}")
print(f"{'SINDy (paper protocol)':<42}{'Rust':>12}{'PySINDy':>12}{'ratio':>9}")
for name in ("translational", "attitude", "full"):
    r, p = rust["fit"][name], py["fit"][name]
    print(f"{'one fit, ' + name + ' support':<42}{r*1e3:>9.3f} ms{p*1e3:>9.1f} ms{p/r:>8.0f}x")
r, p = rust["table"], py["table"]
print(f"{'whole 12-cell table incl. CSV parsing':<42}{r*1e3:>9.1f} ms{p*1e3:>9.1f} ms{p/r:>8.1f}x")
print(f"{'  of which Rust CSV parsing (4 files)':<42}{rust['parse']*1e3:>9.1f} ms")
print(f"{'  12 cells without CSV parsing':<42}{rust['cells']*1e3:>9.1f} ms")
PY
