#!/usr/bin/env bash
# wetdem against LIGGGHTS 3.8 (Debian's liggghts) on the benchmark's system, 2000 spheres
# settling in a closed box from the same state (bench/many_bench.c, bench/liggghts/):
#   1. elastic and frictionless (e = 1, mu = 0): the forces depend on the positions only and the
#      two codes' velocity Verlet steps are the same map. Their trajectories must differ no more
#      than wetdem's own from a copy of the state moved by one unit in the last place (the growth
#      of rounding in this system), and a LIGGGHTS run with E changed by 1e-8 must differ far more;
#   2. damped (e = 0.5, Tsuji damping as LIGGGHTS' model hertz, frictionless): the codes evaluate
#      the damping at other velocities (wetdem at the predicted velocity of the step's end,
#      LIGGGHTS at the half-step velocity; docs/many.md, Time step), so they differ at the step;
#      the difference must shrink at first order as dt is halved, and each code's error against
#      a converged run (wetdem at dt / 32) is measured: wetdem's must not be the larger.
# Checks and figure: figures/liggghts_crosscheck.py -> docs/figures/liggghts_crosscheck.png.
# Usage: scripts/validate.d/47-liggghts.sh PATH_TO_WETDEM_CLI   (from the repository root)
set -euo pipefail
. scripts/piece-start.sh
piece_start 47-liggghts.sh out/validate/liggghts "$@"
deck=$(pwd)/bench/liggghts
lib=$(dirname "$cli")/libwetdem.a
cc -std=c11 -D_DEFAULT_SOURCE -O2 -fopenmp -Iinclude bench/many_bench.c "$lib" \
   -lsundials_cvode -lsundials_nvecserial -lgsl -lgslcblas -linih -lm -o "$out/many_bench"
N=2000
wd() { OMP_NUM_THREADS=1 "$out/many_bench" --n $N --frictionless --settle 0 "$@"; }
lg() { # LIGGGHTS, one rank: dt steps every dump [-var ...]
  local dt=$1 steps=$2 every=$3 dump=$4
  shift 4
  liggghts -in "$deck/frictionless.in" -var deckdir "$deck" -var data "$out/system.data" \
    -var nsettle 0 -var nsteps "$steps" -var dt "$dt" -var every "$every" -var dump "$dump" \
    "$@" -log "$dump.log" -screen none -nocite
}
"$out/many_bench" --n $N --frictionless --restitution 1 --data "$out/system.data"

echo "-- elastic, frictionless: 2000 steps of 1e-5 s in both codes, state every 100 steps"
wd --restitution 1 --steps 2000 --trace "$out/elastic_wetdem.txt" --trace-every 100
wd --restitution 1 --steps 2000 --trace "$out/elastic_wetdem_ulp.txt" --trace-every 100 --perturb
lg 1e-5 2000 100 "$out/elastic_liggghts.txt"
lg 1e-5 2000 100 "$out/elastic_liggghts_E.txt" -var youngs 1.00000001e7

echo "-- damped (e = 0.5), frictionless: 1 ms at dt = 1e-5 ... 1.25e-6 s in both codes"
wd --restitution 0.5 --dt 3.125e-7 --steps 3200 --trace "$out/damped_reference.txt" \
   --trace-every 1600
for dt in 1e-5 5e-6 2.5e-6 1.25e-6; do
  steps=$(awk -v d=$dt 'BEGIN { printf "%d", 1e-3 / d + 0.5 }')
  wd --restitution 0.5 --dt $dt --steps "$steps" --trace "$out/damped_wetdem_$dt.txt" \
     --trace-every $((steps / 2))
  lg $dt "$steps" $((steps / 2)) "$out/damped_liggghts_$dt.txt" -var e 0.5
done
/usr/bin/python3 figures/liggghts_crosscheck.py --dir "$out"
