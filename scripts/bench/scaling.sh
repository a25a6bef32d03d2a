#!/usr/bin/env bash
# `make bench`, SINDy scaling part: `learn sindy --library poly:3 --threshold 0.1 --derivative
# central` against `pysindy.SINDy(PolynomialLibrary(3), STLSQ(0.1)).fit(x, t, u)` on synthetic
# recordings (scripts/bench/scaling_data.py) of ROWS rows × 20 / 120 / 455 cubic features (3 / 7 /
# 12 input columns), in one run on this machine: seconds, peak RSS and the ratios. Rust's time is
# the whole command (reading the CSV included); PySINDy's the fit alone. PySINDy is skipped where its
# library matrix would exceed PYSINDY_MAX_GB (default 4).
#
# SCALING_ROWS="10000 100000 1000000 10000000" scripts/bench/scaling.sh
set -euo pipefail
cd "$(dirname "$0")/../.."

[ -x .venv/bin/python ] || scripts/python-env.sh
rows_list="${SCALING_ROWS:-10000 100000 1000000 10000000}"
pysindy_max_gb="${PYSINDY_MAX_GB:-4}"
data_dir=target/bench-data
mkdir -p "$data_dir"
learn=target/debug/learn

printf '%-10s %-9s %12s %12s %9s %12s %12s %12s %8s\n' rows features "Θ (MB)" "Rust (s)" "RSS MB" "RSS/Θ" "PySINDy (s)" "PySINDy MB" ratio
for rows in $rows_list; do
    for shape in "2 1" "5 2" "10 2"; do
        read -r states controls <<<"$shape"
        csv="$data_dir/scaling-$rows-$states-$controls.csv"
        [ -f "$csv" ] || .venv/bin/python scripts/bench/scaling_data.py "$rows" "$csv" "$states" "$controls"
        state_names=$(seq -s, -f 'x%g' 0 $((states - 1)))
        control_names=$(seq -s, -f 'u%g' 0 $((controls - 1)))
        inputs=$((states + controls))
        features=$(( (inputs + 1) * (inputs + 2) * (inputs + 3) / 6 ))
        matrix_mb=$(python3 -c "print(f'{$rows * $features * 8 / 2**20:.0f}')")
        measured=$( { /usr/bin/time -f '%e %M' "$learn" sindy --quiet --csv "$csv" --state "$state_names" \
            --control "$control_names" --library poly:3 --threshold 0.1 --derivative central >/dev/null; } 2>&1 | tail -1)
        read -r rust_s rust_kib <<<"$measured"
        rust_mb=$((rust_kib / 1024))
        python_s=-; python_mb=-; ratio=-
        if python3 -c "import sys; sys.exit(0 if $rows * $features * 8 <= $pysindy_max_gb * 2**30 else 1)"; then
            json=$(env -u OPENBLAS_CORETYPE -u OPENBLAS_L2_SIZE .venv/bin/python scripts/bench/sindy_scaling.py "$csv" "$states" "$controls")
            python_s=$(python3 -c "import json,sys; print(f\"{json.loads(sys.argv[1])['seconds']:.2f}\")" "$json")
            python_mb=$(python3 -c "import json,sys; print(f\"{json.loads(sys.argv[1])['peak_rss_mb']:.0f}\")" "$json")
            ratio=$(python3 -c "print(f'{$python_s / max($rust_s, 0.01):.1f}x')")
        fi
        rss_ratio=$(python3 -c "print(f'{$rust_mb / max($matrix_mb, 1):.2f}')")
        printf '%-10s %-9s %12s %12s %9s %12s %12s %12s %8s\n' "$rows" "$features" "$matrix_mb" "$rust_s" "$rust_mb" "$rss_ratio" "$python_s" "$python_mb" "$ratio"
    done
done
