#!/usr/bin/env bash
# `make bench`, the mismatch tool against the recording's length: configuration A of the demo
# (experiments/mismatch/configurations/a.json, 50 Hz) with a rotor drag, simulated for SECONDS each
# (3,000 rows to one hour, 180,000 rows, by default) and analysed by `learn mismatch --recording`
# with A's model (over 40,000 rows in parts): wall seconds, peak RSS, milliseconds per row, the
# exponent of time against rows between the shortest and the longest, and the time per flight-hour
# at 50 Hz. One run on this machine; A's model is given the configuration's logger, as the demo
# gives it.
#
# MISMATCH_SECONDS="60 150 300 600 3600" scripts/bench/mismatch_length.sh
set -euo pipefail
cd "$(dirname "$0")/../.."

seconds_list="${MISMATCH_SECONDS:-60 150 300 600 3600}"
learn=target/debug/learn
work=target/bench-mismatch
mkdir -p "$work"
model="$work/model.json"
# A's nominal model with its logger, as the demo writes it for the blind analysis.
python3 - "$model" <<'PY'
import json, sys
model = json.load(open("experiments/mismatch/vehicles/quad-a.json"))
scenario = json.load(open("experiments/mismatch/configurations/a.json"))
model["logger"] = dict(scenario["logger"], command_time_offset_s=0.0,
                       controller_rate_hz=scenario["controller_rate_hz"])
json.dump(model, open(sys.argv[1], "w"), indent=1)
PY

printf '%-10s %8s %10s %9s %9s\n' seconds rows "wall (s)" "RSS MB" "ms/row"
results=()
for seconds in $seconds_list; do
    scenario="$work/a-$seconds.json"
    python3 - "$seconds" "$scenario" <<'PY'
import json, os, sys
seconds, out = float(sys.argv[1]), sys.argv[2]
base = json.load(open("experiments/mismatch/configurations/a.json"))
base["model"] = os.path.abspath("experiments/mismatch/vehicles/quad-a.json")
base["duration_s"] = seconds
base["effects"] = {"linear_drag": {"d": [0.35, 0.35, 0.1]}}
json.dump(base, open(out, "w"), indent=1)
PY
    recording="$work/a-$seconds.csv"
    "$learn" --quiet simulate --scenario "$scenario" --out "$recording" --force >/dev/null
    rows=$(($(wc -l <"$recording") - 1))
    measured=$( { /usr/bin/time -f '%e %M' "$learn" --quiet mismatch --recording "$recording" --model "$model" \
        --out "$work/out-$seconds" --force >/dev/null; } 2>&1 | tail -1)
    read -r wall kib <<<"$measured"
    printf '%-10s %8s %10s %9s %9.2f\n' "$seconds" "$rows" "$wall" $((kib / 1024)) \
        "$(python3 -c "print(1e3 * $wall / $rows)")"
    results+=("$rows:$wall")
done
python3 - "${results[@]}" <<'PY'
import math, sys
points = [tuple(map(float, p.split(":"))) for p in sys.argv[1:]]
(n0, t0), (n1, t1) = points[0], points[-1]
if len(points) > 1:
    measured = "measured" if n1 >= 180000 else "at the longest's rate"
    print(f"time grows as rows^{math.log(t1 / t0) / math.log(n1 / n0):.2f} from {n0:.0f} to {n1:.0f} rows;"
          f" one flight-hour at 50 Hz (180,000 rows), {measured}: {t1 / n1 * 180000 / 60:.1f} min")
PY
