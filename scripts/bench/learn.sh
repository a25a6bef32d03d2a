#!/usr/bin/env bash
# Time per LeARN meta-iteration (exact second order, paper sizes, full formulation, 4 tasks x 64
# support / 64 query points, one inner round): Rust (dev profile, which optimises the learn crate)
# against the JAX reference scripts/bench/learn.py, on the same cores. Each side runs BENCH_RUNS
# times (alternating), each run times REPEATS iterations; the ratio uses the minimum over all of
# them (the least-disturbed measurement on a shared machine) and the median is printed beside it.
set -euo pipefail
cd "$(dirname "$0")/../.."
ARGS=(${BENCH_ARGS:-4 64 64 1 50})
RUNS=${BENCH_RUNS:-3}
if [ ! -x .venv/bin/python ] || ! .venv/bin/python -c "import jax" 2>/dev/null; then
    scripts/python-env.sh
fi
cargo build -q -p learn --example meta_iteration_timing
echo "load before: $(uptime)"
rust_runs=()
jax_runs=()
for _ in $(seq "$RUNS"); do
    rust_runs+=("$(target/debug/examples/meta_iteration_timing "${ARGS[@]}" 2>/dev/null | tail -1)")
    jax_runs+=("$(.venv/bin/python scripts/bench/learn.py "${ARGS[@]}" 2>/dev/null | tail -1)")
done
echo "load after:  $(uptime)"
for r in "${rust_runs[@]}"; do echo "rust: $r"; done
for j in "${jax_runs[@]}"; do echo "jax:  $j"; done
python3 - "${#rust_runs[@]}" "${rust_runs[@]}" "${jax_runs[@]}" <<'PY'
import json, sys
n = int(sys.argv[1])
rust = [json.loads(a) for a in sys.argv[2:2 + n]]
jax = [json.loads(a) for a in sys.argv[2 + n:]]
assert rust[0]["parameters"] == jax[0]["parameters"], (rust[0]["parameters"], jax[0]["parameters"])
r_min = min(x["seconds_per_iteration_min"] for x in rust)
j_min = min(x["seconds_per_iteration_min"] for x in jax)
r_med = min(x["seconds_per_iteration"] for x in rust)
j_med = min(x["seconds_per_iteration"] for x in jax)
r1_min = min(x["seconds_per_iteration_one_thread_min"] for x in rust)
first = rust[0]
print(f"LeARN meta-iteration ({first['tasks']} tasks, {first['support']}/{first['query']} points, "
      f"{first['inner_rounds']} inner round, {first['parameters']} parameters, second order)")
print(f"  minimum: Rust {r_min*1e3:.2f} ms (one thread {r1_min*1e3:.2f} ms), JAX {j_min*1e3:.2f} ms; "
      f"speed-up of Rust over JAX: {j_min/r_min:.2f}x ({'Rust' if r_min < j_min else 'JAX'} faster; target >= 5x)")
print(f"  median:  Rust {r_med*1e3:.2f} ms, JAX {j_med*1e3:.2f} ms; ratio {j_med/r_med:.2f}x")
# Each Rust run with the JAX run that followed it (the host's speed drifts over seconds).
pairs = sorted(j["seconds_per_iteration_min"] / r["seconds_per_iteration_min"] for r, j in zip(rust, jax))
print(f"  run by run (minimum of each run, Rust run then JAX run): ratios {', '.join(f'{p:.2f}' for p in pairs)}; "
      f"median {pairs[len(pairs) // 2]:.2f}x")
PY
