#!/usr/bin/env bash
# Many-particle runs from the command line with the five shipped scenarios: the Stokes
# cradle (momentum handed along a chain of wet spheres), wet granular settling in a box,
# agglomeration in a periodic box, settling onto a rough base of fixed spheres read from a
# file, and grains on that base tilted into a chute, wet and dry. Run directories in
# out/validate/many/, figures in docs/figures/many_*.png (figures/many_figs.py, which checks
# on the outputs that the cradle conserves momentum and hands it to the last sphere, that the
# energy budget closes, that the bed comes to rest, that the agglomerates grow, that the base
# stays put, and that on the chute the wet layer stops while the dry one flows) and what they
# show in docs/many.md.
# OMP_WAIT_POLICY=passive: on a shared machine, spinning OpenMP threads slow the run several
# fold (docs/many.md); the cradle (5 spheres) runs on one thread.
# Usage: scripts/validate.d/40-many.sh PATH_TO_WETDEM_CLI   (from the repository root)
set -euo pipefail
. scripts/piece-start.sh
piece_start 40-many.sh out/validate/many "$@"

echo "-- Stokes cradle: five coated steel spheres, the first strikes at 0.4 m/s"
OMP_NUM_THREADS=1 "$cli" run $S/many_stokes_cradle.ini --out "$out/cradle"
echo "-- wet granular settling: 2000 spheres in a box periodic in x and y"
"$cli" run $S/many_settling.ini --out "$out/settling"
echo "-- agglomeration: 400 wet spheres in a periodic box"
"$cli" run $S/many_agglomeration.ini --out "$out/agglomeration"
echo "-- rough base: 400 wet spheres settle onto 64 glued spheres read from a file"
"$cli" run $S/many_rough_base.ini --out "$out/rough_base"
echo "-- chute: 300 wet spheres on the rough base under gravity tilted by 30 deg, and dry"
"$cli" run $S/many_chute.ini --out "$out/chute"
"$cli" run $S/many_chute.ini --out "$out/chute_dry" --set "models.force=hertz mindlin" \
  --set material.wetglass.film=0
/usr/bin/python3 figures/many_figs.py --dir "$out"
