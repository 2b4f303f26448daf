#!/usr/bin/env bash
# Tracking demo (Punch et al. 2023 Sec. 3.2 and Fig. 5; docs/tracking.md, "Demo"): simulates
# the Punch DB-C collision at St_n = 3 and 45 deg (examples/tracks/punch_45deg.ini), renders
# the three painted dots of both spheres at 5000 frames/s and 175 um/pixel with 0.05 px noise
# into examples/tracks/punch_45deg.csv (tools/track_render.py; deterministic, so the committed
# file is reproduced unless the engine changed), tracks them with `wetdem track`, and plots
# the raw positions, vx, vy and omega per frame with the fitted lines into
# docs/figures/punch_track.png (figures/punch_track.py, which fails the piece when the refitted
# lines disagree with the summary or the tracked e_n, spins or impact angle miss the
# simulation's by more than the tolerances tests/test_track.c derives).
# Usage: scripts/validate.d/25-track.sh PATH_TO_WETDEM_CLI   (from the repository root)
set -euo pipefail
cli=${1:?usage: 25-track.sh PATH_TO_WETDEM_CLI}
py=/usr/bin/python3
out=out/validate/track
dots=examples/tracks/punch_45deg.csv
mkdir -p "$out"

"$cli" run examples/tracks/punch_45deg.ini --out "$out/run" > "$out/run.txt"
$py tools/track_render.py "$out/run/trajectory.csv" --out "$dots"
# m = 7960 kg/m^3 x 4/3 pi (12.7 mm)^3 = 0.06830 kg (Punch Table 1), mu = 10 Pa s
"$cli" track "$dots" --fps 5000 --pixel-size 175e-6 --radius 12.7e-3 --mass 0.06830 \
  --viscosity 10 --frames "$out/frames.csv" --json > "$out/track.json"
cat "$out/track.json"
$py figures/punch_track.py --dots "$dots" --frames "$out/frames.csv" \
  --summary "$out/track.json" --sim "$out/run/summary.json" --png docs/figures/punch_track.png
