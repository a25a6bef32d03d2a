#!/usr/bin/env bash
# Creates the Python virtual environments of the reference scripts (all git-ignored):
#   scripts/python-env.sh        -> .venv        PySINDy and JAX (small, CPU-only wheels)
#   scripts/python-env.sh torch  -> .venv-torch  PyTorch for the LeARN bench's PyTorch reference.
#   scripts/python-env.sh ulog   -> .venv-ulog   pyulog, the ULog reader's reference (scripts/golden/ulog_golden.py)
# PyPI's Linux torch wheel depends on the CUDA libraries, so .venv-torch downloads ~2.5 GB and
# takes ~5.3 GB on disk; it is kept apart so that the shared .venv stays small.
set -euo pipefail
cd "$(dirname "$0")/.."

if [ "${1:-}" = ulog ]; then
    VENV=.venv-ulog
    PACKAGES=(
        pyulog==1.3.0
        numpy==2.4.6
    )
elif [ "${1:-}" = torch ]; then
    VENV=.venv-torch
    PACKAGES=(
        # learn: PyTorch (torch.func) reference of the LeARN meta-iteration (scripts/bench/learn_torch.py)
        torch==2.15.0
        numpy==2.4.6
    )
else
    VENV=.venv
    PACKAGES=(
        # sindy: PySINDy reference (scripts/golden/sindy*, scripts/bench/sindy*)
        pysindy==2.1.0
        scikit-learn==1.9.1
        scipy==1.17.1
        numpy==2.4.6
        pandas==3.1.1
        # data: Parquet files for the ingestion bench and tests' fixtures (scripts/bench/parquet*)
        pyarrow==26.0.1
        # learn: JAX reference of the LeARN meta-iteration (scripts/bench/learn*)
        jax[cpu]==0.10.2
    )
fi

if [ ! -x "$VENV/bin/python" ]; then
    python3 -m venv "$VENV"
fi
"$VENV/bin/python" -m pip install -q --no-cache-dir "${PACKAGES[@]}"
