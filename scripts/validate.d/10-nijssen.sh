#!/usr/bin/env bash
# Nijssen et al. (2023) binary-collision validation: Figs. 2-5 and a particle-wall collision
# at St = 50. CSV and run directories in out/validate/nijssen/, figures in docs/figures/
# (figures/nijssen_fig*.py), what they show in docs/validation.md. Each figure script checks
# the paper's statements on the data and fails the piece when one does not hold.
# Usage: scripts/validate.d/10-nijssen.sh PATH_TO_WETDEM_CLI   (from the repository root)
set -euo pipefail
cli=${1:?usage: 10-nijssen.sh PATH_TO_WETDEM_CLI}
py=/usr/bin/python3
out=out/validate/nijssen
S=examples/scenarios
mkdir -p "$out"

echo "-- Fig. 2: gap vs time, Delrin, head-on"
for st in 1 3 10 30 100 1000; do
  "$cli" run $S/nijssen_head_on.ini --set collision.stokes=$st --out "$out/fig2_st$st" \
    --json > /dev/null
done
$py figures/nijssen_fig2.py --dir "$out"

echo "-- Fig. 3: e vs St, four materials, head-on (60 St from 1 to 3000)"
for m in steel1 steel2 glass delrin; do
  "$cli" sweep $S/nijssen_head_on.ini --set collision.striker=$m --param collision.stokes \
    --values 1:3000:60 --log --out "$out/fig3_$m.csv"
done
$py figures/nijssen_fig3.py --dir "$out"

echo "-- Fig. 4: e vs St for Delrin at several roughness values; plateau h_sigma = h_eps"
for s in 10e-9 50e-9 200e-9 796e-9 2000e-9; do
  nm=$($py -c "print(f'{$s * 1e9:g}')")
  "$cli" sweep $S/nijssen_roughness.ini --set material.rough.roughness=$s \
    --param collision.stokes --values 1:3000:40 --log --out "$out/fig4_sigma$nm.csv"
done
for st in 30 100 1000; do
  "$cli" sweep $S/nijssen_roughness.ini --set collision.stokes=$st \
    --param material.rough.roughness --values 1e-9:3e-6:30 --log --out "$out/fig4_st$st.csv"
done
# plateau line: each St with sigma = sigma_eps(St) = h_eps(v(St)) (Nijssen Eq. 5, fifth root)
plateau="$out/fig4_plateau.csv"
{
  echo "# wetdem Fig. 4 plateau: runs with sigma = h_eps(St) ($("$cli" --version))"
  echo "stokes [-],sigma_eps [m],e [-]"
  for st in $($py -c "import numpy as n; print(' '.join(f'{x:.6g}' for x in n.logspace(0, n.log10(3000), 25)))"); do
    sig=$($py -c "import sys; sys.path.insert(0, 'figures'); import nijssen_fig4 as f; print(f'{float(f.sigma_eps($st)):.6e}')")
    e=$("$cli" run $S/nijssen_roughness.ini --set collision.stokes=$st \
        --set material.rough.roughness=$sig --json |
        $py -c "import json, sys; print(json.load(sys.stdin)['result']['e'])")
    echo "$st,$sig,$e"
  done
} > "$plateau.tmp" && mv "$plateau.tmp" "$plateau"
$py figures/nijssen_fig4.py --dir "$out"

echo "-- Fig. 5: rebound angle vs impact angle in the three St_n ranges of the caption"
# angle_deg is the impact angle at contact of the straight-line approach (as Fig. 1c): 0 to 85
# deg in steps of 5 deg.
for st in 10 15 20 25; do
  "$cli" sweep $S/nijssen_oblique.ini --set collision.striker=steel1 \
    --set fluid.preset=glycerol80 --set collision.stokes=$st \
    --param collision.angle_deg --values 0:85:18 --out "$out/fig5_low_st$st.csv"
done
for st in 40 100 200; do
  "$cli" sweep $S/nijssen_oblique.ini --set collision.stokes=$st \
    --param collision.angle_deg --values 0:85:18 --out "$out/fig5_mid_st$st.csv"
done
for st in 500 1000 2400; do
  "$cli" sweep $S/nijssen_oblique.ini --set collision.striker=steel1 --set collision.stokes=$st \
    --param collision.angle_deg --values 0:85:18 --out "$out/fig5_high_st$st.csv"
done
$py figures/nijssen_fig5.py --dir "$out"

echo "-- particle-wall collision at St = 50 (lubrication must act on walls)"
"$cli" run $S/wall_collision.ini --out "$out/wall_st50" --json > "$out/wall_st50.json"
"$cli" run $S/wall_collision.ini --set fluid.viscosity=1e-9 --set collision.speed=0.004554379 \
  --json > "$out/wall_dry.json"
$py - "$out/wall_st50.json" "$out/wall_dry.json" <<'PY'
import json, sys
wet = json.load(open(sys.argv[1]))["result"]
dry = json.load(open(sys.argv[2]))["result"]
print(f"  wall, St = 50: e = {wet['e']:.4f}, e_n = {wet['e_n']:.4f}, min gap {wet['min_gap']:.3g} m, "
      f"interaction {wet['interaction_duration']:.4g} s, contact {wet['contact_duration']:.3g} s")
print(f"  same speed, viscosity 1e-9 Pa s: e = {dry['e']:.4f}")
ok = wet["e"] < 0.85 * 0.97 and dry["e"] > 0.95 * 0.97
print(f"  [{'ok' if ok else 'FAIL'}] wall: lubrication acts, e(St=50) = {wet['e']:.3f} clearly "
      f"below e_dry = 0.97, while the nearly dry run gives {dry['e']:.3f}")
sys.exit(0 if ok else 1)
PY
