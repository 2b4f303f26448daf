#!/usr/bin/env bash
# Calibration example (docs/calibration.md, "Example"): fits the glass-transition pressure
# P_gt of Punch Eq. 14 to examples/fit/punch_0deg.csv (head-on e_n simulated at 11.6 MPa plus
# 0.02 noise) with examples/fit/punch_db_c.ini, plots data, fitted curve and residuals into
# docs/figures/fit_example.png (figures/fit_plot.py) and fails unless the fit recovers
# 11.6 MPa within 3 of its reported standard errors.
# Usage: scripts/validate.d/26-fit.sh PATH_TO_WETDEM_CLI   (from the repository root)
set -euo pipefail
cli=${1:?usage: 26-fit.sh PATH_TO_WETDEM_CLI}
py=/usr/bin/python3
out=out/validate/fit
mkdir -p "$out"

"$cli" fit examples/fit/punch_db_c.ini --data examples/fit/punch_0deg.csv --fit glass.p_gt \
  --init 4e6 --out "$out/fit.csv" --curve "$out/curve.csv" > "$out/summary.csv"
cat "$out/summary.csv"
$py figures/fit_plot.py "$out/fit.csv" --curve "$out/curve.csv" --summary "$out/summary.csv" \
  --png docs/figures/fit_example.png --title "P_gt fitted to examples/fit/punch_0deg.csv"
$py - "$out/summary.csv" <<'PY'
import sys
rows = [ln.strip().split(",") for ln in open(sys.argv[1]) if ln.strip() and ln[0] != "#"]
value, se = float(rows[1][2]), float(rows[1][3])
z = (value - 11.6e6) / se
print(f"P_gt = {value:.4g} +- {se:.2g} Pa, truth 11.6 MPa: z = {z:.2f}")
sys.exit(0 if abs(z) < 3 else 1)
PY
