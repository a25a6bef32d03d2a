#!/usr/bin/env bash
# Time per LeARN meta-iteration (exact second order, paper sizes, full formulation, 4 tasks x 64
# support / 64 query points, one inner round): Rust (dev profile, which optimises the learn crate)
# against three references of the same computation on the same cores: JAX (jit,
# scripts/bench/learn.py), PyTorch torch.func run eagerly (the issue's reference,
# scripts/bench/learn_torch.py) and the same PyTorch step under torch.compile. Each side runs
# BENCH_RUNS times (alternating), each run times REPEATS iterations; the ratio uses the minimum over
# all of them (the least-disturbed measurement on a shared machine) and the median is printed beside
# it. BENCH_TORCH=0 leaves PyTorch out (its virtual environment downloads ~2.5 GB on first use).
set -euo pipefail
cd "$(dirname "$0")/../.."
ARGS=(${BENCH_ARGS:-4 64 64 1 50})
RUNS=${BENCH_RUNS:-3}
TORCH=${BENCH_TORCH:-1}
if [ ! -x .venv/bin/python ] || ! .venv/bin/python -c "import jax" 2>/dev/null; then
    scripts/python-env.sh
fi
if [ "$TORCH" = 1 ] && { [ ! -x .venv-torch/bin/python ] || ! .venv-torch/bin/python -c "import torch" 2>/dev/null; }; then
    # PyTorch with its CUDA dependencies: ~2.5 GB to download, ~5.3 GB installed.
    free_gb=$(( $(df --output=avail -k . | tail -1) / 1048576 ))
    if [ "$free_gb" -lt 8 ]; then
        echo "leaving PyTorch out: .venv-torch needs ~5.3 GB and only ${free_gb} GB are free (BENCH_TORCH=0 silences this)"
        TORCH=0
    else
        echo "creating .venv-torch (PyTorch with its CUDA dependencies, ~2.5 GB download; BENCH_TORCH=0 skips it)"
        scripts/python-env.sh torch
    fi
fi
cargo build -q -p learn --example meta_iteration_timing
echo "load before: $(uptime)"
runs=()
for _ in $(seq "$RUNS"); do
    runs+=("$(target/debug/examples/meta_iteration_timing "${ARGS[@]}" 2>/dev/null | tail -1)")
    runs+=("$(.venv/bin/python scripts/bench/learn.py "${ARGS[@]}" 2>/dev/null | tail -1)")
    if [ "$TORCH" = 1 ]; then
        runs+=("$(.venv-torch/bin/python scripts/bench/learn_torch.py "${ARGS[@]}" eager 2>/dev/null | tail -1)")
        runs+=("$(.venv-torch/bin/python scripts/bench/learn_torch.py "${ARGS[@]}" compile 2>/dev/null | tail -1)")
    fi
done
echo "load after:  $(uptime)"
for r in "${runs[@]}"; do echo "$r"; done
python3 - "${runs[@]}" <<'PY'
import json, sys
runs = [json.loads(a) for a in sys.argv[1:]]
by_name = {}
for run in runs:
    by_name.setdefault(run["implementation"], []).append(run)
rust = by_name.pop("rust")
first = rust[0]
for name, others in by_name.items():
    assert others[0]["parameters"] == first["parameters"], (name, others[0]["parameters"], first["parameters"])
r_min = min(x["seconds_per_iteration_min"] for x in rust)
r_med = min(x["seconds_per_iteration"] for x in rust)
r1_min = min(x["seconds_per_iteration_one_thread_min"] for x in rust)
print(f"LeARN meta-iteration ({first['tasks']} tasks, {first['support']}/{first['query']} points, "
      f"{first['inner_rounds']} inner round, {first['parameters']} parameters, second order)")
print(f"  Rust: minimum {r_min*1e3:.2f} ms (one thread {r1_min*1e3:.2f} ms), median {r_med*1e3:.2f} ms")
labels = {"jax": "JAX (jit)", "torch-eager": "PyTorch (torch.func, eager)",
          "torch-compile": "PyTorch (torch.compile)"}
for name, others in by_name.items():
    o_min = min(x["seconds_per_iteration_min"] for x in others)
    o_med = min(x["seconds_per_iteration"] for x in others)
    # Each Rust run with the reference run that followed it (the host's speed drifts over seconds).
    pairs = sorted(o["seconds_per_iteration_min"] / r["seconds_per_iteration_min"] for r, o in zip(rust, others))
    target = " (target >= 5x)" if name == "torch-eager" else ""
    print(f"  {labels.get(name, name)}: minimum {o_min*1e3:.2f} ms, median {o_med*1e3:.2f} ms; Rust is "
          f"{o_min/r_min:.2f}x faster on the minimum{target}, {o_med/r_med:.2f}x on the median; run by run "
          f"{', '.join(f'{p:.2f}' for p in pairs)} (median {pairs[len(pairs) // 2]:.2f}x)")
PY
