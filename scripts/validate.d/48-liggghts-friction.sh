#!/usr/bin/env bash
# wetdem against LIGGGHTS 3.8 (Debian's liggghts) with friction: isolated oblique collisions of
# equal spheres (one striker on a sphere at rest, impact angles 2-80 deg, without and with
# spin), elastic (e = 1: no dashpots, and both codes' Coulomb limits are mu times the Hertz
# force), Hertz + Mindlin history (`hertz mindlin`, LIGGGHTS `model hertz tangential
# history`), from one state written for both codes by figures/liggghts_friction.py:
#   stiff (E = 70 GPa, delta/R = 5e-5) at 25 ... 1600 steps per contact time: the codes
#     differ at first order in dt (the velocity the spring advances with) and tend to one
#     answer; LIGGGHTS with nu or mu perturbed does not (the control); the sliding pairs give
#     the rigid-body closed form;
#   soft (the benchmark's E = 10 MPa, delta/R ~ 1e-2): the difference left at dt = 0 is the
#     lever arm of the tangential force (R in wetdem, R - delta/2 in LIGGGHTS).
# Checks and figure: figures/liggghts_friction.py -> docs/figures/liggghts_friction.png.
# Usage: scripts/validate.d/48-liggghts-friction.sh PATH_TO_WETDEM_CLI   (from the repository root)
set -euo pipefail
. scripts/piece-start.sh
piece_start 48-liggghts-friction.sh out/validate/liggghts_friction "$@"
deck=$(pwd)/bench/liggghts
py=/usr/bin/python3
$py figures/liggghts_friction.py setup "$out"
wd() { # set name dt steps E e: wetdem on the state of the set, into $out/wetdem_NAME
  local set=$1 name=$2 dt=$3 steps=$4 E=$5 e=$6
  read -r x1 y1 z1 <"$out/$set.box"
  cat >"$out/wetdem_$set.ini" <<INI
[box]
size_x = $x1
size_y = $y1
size_z = $z1
[walls]
faces = none
[material.m]
density = 2500
youngs_modulus = $E
poisson_ratio = 0.3
restitution = $e
friction_dry = 0.2
[models]
force = hertz mindlin
[model.hertz]
damping = tsuji
[read.pairs]
file = $set.csv
material = m
[run]
energy_budget = no
[dump]
csv = none
checkpoint = none
summary = none
INI
  OMP_NUM_THREADS=1 "$cli" run "$out/wetdem_$set.ini" --out "$out/wetdem_$name" \
    --set run.dt=$dt --set run.steps=$steps --set dump.vtk_every=$steps >/dev/null \
    2>"$out/wetdem_$name.err" || { cat "$out/wetdem_$name.err" >&2; exit 1; }
}
lg() { # set name dt steps E e [-var ...]: LIGGGHTS, one rank, into $out/liggghts_NAME.dump
  local set=$1 name=$2 dt=$3 steps=$4 E=$5 e=$6
  shift 6
  liggghts -in "$deck/friction.in" -var data "$out/$set.data" -var nsteps "$steps" \
    -var dt "$dt" -var dump "$out/liggghts_$name.dump" -var youngs "$E" -var e "$e" "$@" \
    -log "$out/liggghts_$name.log" -screen none -nocite
}
echo "-- 22 pairs, mu = 0.2: stiff (e = 1 and 0.5) and soft (e = 1), both codes at each step"
while read -r set name dt steps E e; do
  wd "$set" "$name" "$dt" "$steps" "$E" "$e"
  lg "$set" "$name" "$dt" "$steps" "$E" "$e"
  if [ "$name" = stiff_800 ] || [ "$name" = stiff_1600 ]; then # the controls
    lg "$set" "${name}_nu" "$dt" "$steps" "$E" "$e" -var nu 0.31
    lg "$set" "${name}_mu" "$dt" "$steps" "$E" "$e" -var mu 0.202
  fi
done <"$out/runs.txt"
$py figures/liggghts_friction.py check "$out"
