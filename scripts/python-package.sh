#!/usr/bin/env bash
# The Python package learn-sysid (crates/python) in `make test`: a git-ignored virtual
# environment (.venv-python) with the test suite's pinned requirements, the package staged in
# target/python from its Python sources and the extension module the workspace build made
# (target/debug/lib_native.so, no second build), and the pytest suite on it.
#   scripts/python-package.sh          the suite
#   scripts/python-package.sh stage    only the staged package (for the bench's environment)
# Users install the package with pip instead: python -m venv .venv && .venv/bin/pip install ./crates/python
set -euo pipefail
cd "$(dirname "$0")/.."

stage() {
    local extension=target/debug/lib_native.so staged=target/python/learn_sysid
    [ -f "$extension" ] || { echo "$extension: build the workspace first (make build)" >&2; exit 1; }
    rm -rf "$staged"
    mkdir -p "$staged"
    cp crates/python/learn_sysid/*.py "$staged/"
    cp "$extension" "$staged/_native.abi3.so"
}
if [ "${1:-}" = stage ]; then
    stage
    exit 0
fi

VENV=.venv-python
PACKAGES=(
    pytest==9.2.0
    # the reference the suite compares with
    pysindy==2.1.0
    scikit-learn==1.9.1
    scipy==1.17.1
    numpy==2.4.6
)
if [ ! -x "$VENV/bin/python" ]; then
    python3 -m venv "$VENV"
fi
# pip's own check of what is installed makes a second run fast.
"$VENV/bin/python" -m pip install -q --disable-pip-version-check "${PACKAGES[@]}"

stage

PYTHONPATH="target/python${PYTHONPATH:+:$PYTHONPATH}" LEARN_BINARY="$PWD/target/debug/learn" \
    "$VENV/bin/python" -m pytest -q -p no:cacheprovider crates/python/tests
