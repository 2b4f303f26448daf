#!/usr/bin/env bash
# wetdem against LIGGGHTS 3.8 (Debian's liggghts) with friction: isolated oblique collisions of
# equal spheres (one striker on a sphere at rest, impact angles 2-80 deg, without and with
# spin), Hertz + Mindlin history (`hertz mindlin` with `hertz.damping = tsuji`, LIGGGHTS
# `model hertz tangential history`), from one state written for both codes by
# figures/liggghts_friction.py (`setup`, with wetdem's scenarios and the list of runs):
#   stiff, e = 1 (E = 70 GPa, delta/R = 5e-5; no dashpots, and both codes' Coulomb limits are
#     mu times the Hertz force) at 25 ... 1600 steps per contact time: both springs advance
#     with the slip of the half-step velocities, so the codes differ at every dt by the lever
#     arm of the tangential force alone (R in wetdem, R - delta/2 in LIGGGHTS; 1e-5 V_N) but
#     for the spring's rotation against projection (<= 7e-13 V_N); each code is second order;
#     LIGGGHTS with nu or mu perturbed is far off (the controls); the sliding pairs give the
#     rigid-body closed form;
#   soft, e = 1 (the benchmark's E = 10 MPa, delta/R ~ 1e-2): the lever arm, larger;
#   stiff, e = 0.5: the dashpots' velocity (first order) and the Coulomb limits' conventions,
#     which are what is left at dt = 0.
# Checks and figure: figures/liggghts_friction.py check -> docs/figures/liggghts_friction.png.
# Usage: scripts/validate.d/48-liggghts-friction.sh PATH_TO_WETDEM_CLI   (from the repository root)
set -euo pipefail
. scripts/piece-start.sh
piece_start 48-liggghts-friction.sh out/validate/liggghts_friction "$@"
deck=$(pwd)/bench/liggghts
py=/usr/bin/python3
$py figures/liggghts_friction.py setup "$out"
echo "-- 22 pairs: stiff (e = 1 and 0.5) and soft (e = 1), both codes at each step"
grep -v '^#' "$out/runs.txt" | while read -r name set dt steps e E nu mu codes; do
  if [ "$codes" = both ]; then
    OMP_NUM_THREADS=1 "$cli" run "$out/wetdem_$set.ini" --out "$out/wetdem_$name" \
      --set material.m.restitution="$e" --set run.dt="$dt" --set run.steps="$steps" \
      --set dump.vtk_every="$steps" >/dev/null 2>"$out/wetdem_$name.err" \
      || { cat "$out/wetdem_$name.err" >&2; exit 1; }
  fi
  liggghts -in "$deck/friction.in" -var data "$out/$set.data" -var nsteps "$steps" \
    -var dt "$dt" -var e "$e" -var youngs "$E" -var nu "$nu" -var mu "$mu" \
    -var dump "$out/liggghts_$name.dump" -log "$out/liggghts_$name.log" -screen none -nocite
done
$py figures/liggghts_friction.py check "$out"
