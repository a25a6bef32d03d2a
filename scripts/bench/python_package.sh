#!/usr/bin/env bash
# `make bench`, Python package part: learn-sysid (crates/python, staged from the workspace build)
# against PySINDy from the same Python process (scripts/bench/python_package.py): the paper's
# support-segment fit, the 100,000-row × 455-feature fit, the call overhead; ratios printed.
# Needs the flight data (`make data`) and .venv (scripts/python-env.sh, created here if missing).
set -euo pipefail
cd "$(dirname "$0")/../.."

[ -x .venv/bin/python ] || scripts/python-env.sh
data_dir="${NEURAL_FLY_DIR:-data/neural-fly}"
scripts/python-package.sh stage
json=$(PYTHONPATH=target/python env -u OPENBLAS_CORETYPE -u OPENBLAS_L2_SIZE \
    .venv/bin/python scripts/bench/python_package.py "$data_dir")

JSON="$json" python3 - <<'PY'
import json, os
b = json.loads(os.environ["JSON"])
s, l = b["support"], b["large"]
print(f"{'learn-sysid from Python':<56}{'learn-sysid':>13}{'PySINDy':>12}{'ratio':>8}")
print(f"{'one support segment (' + str(s['rows']) + ' rows x ' + str(s['features']) + ' features), SINDy.fit':<56}"
      f"{s['learn_sysid_s']*1e3:>10.2f} ms{s['pysindy_s']*1e3:>9.1f} ms{s['pysindy_s']/s['learn_sysid_s']:>7.1f}x")
print(f"{'  the same, pysindy.SINDy with learn_sysid.STLSQ':<56}"
      f"{s['pysindy_hosting_our_stlsq_s']*1e3:>10.2f} ms{s['pysindy_s']*1e3:>9.1f} ms"
      f"{s['pysindy_s']/s['pysindy_hosting_our_stlsq_s']:>7.1f}x")
print(f"{str(l['rows']) + ' rows x ' + str(l['features']) + ' features, SINDy.fit from arrays':<56}"
      f"{l['learn_sysid_s']:>11.2f} s{l['pysindy_s']:>10.1f} s{l['pysindy_s']/l['learn_sysid_s']:>7.1f}x")
print(f"call overhead: SINDy.fit {l['learn_sysid_s']*1e3:.0f} ms against the extension's fit "
      f"{l['extension_call_s']*1e3:.0f} ms ({(l['learn_sysid_s']-l['extension_call_s'])*1e3:.0f} ms); "
      f"a 50-row fit {b['tiny_fit_s']*1e6:.0f} us")
print(f"largest coefficient difference to PySINDy: support {s['largest_coefficient_difference']:.1e}, "
      f"large {l['largest_coefficient_difference']:.1e} (largest coefficient {l['largest_coefficient']:.2f})")
PY
