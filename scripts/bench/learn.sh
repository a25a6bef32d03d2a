#!/usr/bin/env bash
# Time per LeARN meta-iteration (exact second order, paper sizes, full formulation, 4 tasks x 64
# support / 64 query points, one inner round): Rust (dev profile, which optimises the learn crate)
# against the JAX reference scripts/bench/learn.py, on the same cores. Prints both and the ratio.
set -euo pipefail
cd "$(dirname "$0")/../.."
ARGS=(${BENCH_ARGS:-4 64 64 1 20})
if [ ! -x .venv/bin/python ] || ! .venv/bin/python -c "import jax" 2>/dev/null; then
    scripts/python-env.sh
fi
rust=$(cargo run -q -p learn --example meta_iteration_timing -- "${ARGS[@]}" 2>/dev/null | tail -1)
jax=$(.venv/bin/python scripts/bench/learn.py "${ARGS[@]}" 2>/dev/null | tail -1)
echo "rust: $rust"
echo "jax:  $jax"
python3 - "$rust" "$jax" <<'PY'
import json, sys
rust, jax = (json.loads(a) for a in sys.argv[1:])
assert rust["parameters"] == jax["parameters"], (rust["parameters"], jax["parameters"])
r, j = rust["seconds_per_iteration"], jax["seconds_per_iteration"]
print(f"LeARN meta-iteration ({rust['tasks']} tasks, {rust['support']}/{rust['query']} points, "
      f"{rust['inner_rounds']} inner round, {rust['parameters']} parameters, second order): "
      f"Rust {r*1e3:.2f} ms, JAX {j*1e3:.2f} ms; speed-up of Rust over JAX: {j/r:.2f}x "
      f"({'Rust' if r < j else 'JAX'} faster; target >= 5x)")
PY
