#!/usr/bin/env bash
# Creates the one shared Python virtual environment of the reference scripts at .venv (git-ignored).
# Helpers append their pinned packages to PACKAGES. No torch.
set -euo pipefail
cd "$(dirname "$0")/.."

PACKAGES=(
    # sindy: PySINDy reference (scripts/golden/sindy*, scripts/bench/sindy*)
    pysindy==2.1.0
    scikit-learn==1.9.1
    scipy==1.17.1
    numpy==2.4.6
    pandas==3.1.1
    # learn: JAX reference of the LeARN meta-iteration (scripts/bench/learn*)
    jax[cpu]==0.10.2
)

if [ ! -x .venv/bin/python ]; then
    python3 -m venv .venv
fi
.venv/bin/pip install -q "${PACKAGES[@]}"
