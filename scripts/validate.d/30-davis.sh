#!/usr/bin/env bash
# Davis (2023) three wet spheres with the pairwise engine: snapshot sequences (stick / FA with
# a partner change, PA, FS, theta_23,0 = -45 deg), e_12,w and e_23,w vs St_n with the
# two-sphere oblique and head-on results beside them, and the effects of Ca, impact angle
# (curves and a St_n x angle outcome map), film thickness, h_min, friction; gap vs time; the
# energy budget over time (St_n = 2 at Ca = 1000 and in a deep capillary well, Ca = 0.01).
# CSV in out/validate/davis/, figures in docs/figures/davis_*.png (figures/davis_figs.py,
# which checks stated behaviour on the data and fails the piece when it does not hold),
# explanations in docs/validation_davis.md.
# Usage: scripts/validate.d/30-davis.sh PATH_TO_WETDEM_CLI   (from the repository root)
set -euo pipefail
cli=${1:?usage: 30-davis.sh PATH_TO_WETDEM_CLI}
out=out/validate/davis
S=examples/scenarios/davis_three.ini
mkdir -p "$out"

st() { # NAME [--set ...]: e_ij,w and outcome over 0.3 <= St_n <= 60 (log, 80 values)
  local name=$1
  shift
  "$cli" sweep $S "$@" --param davis.stokes --values 0.3:60:80 --log --out "$out/$name.csv"
}

echo "-- snapshot runs (trajectories and event logs)"
snap() { # NAME [--set ...]
  local name=$1
  shift
  "$cli" run $S "$@" --set output.trajectory_interval=0 --out "$out/snap_$name" >/dev/null
}
snap stick --set davis.stokes=2
snap pa --set davis.stokes=7
snap fs --set davis.stokes=30
snap theta45 --set davis.stokes=7 --set davis.theta23_deg=-45
# the energy budget over time, rows every 1 us (t* = 2.9e-4) to resolve the first approach
"$cli" run $S --set davis.stokes=2 --set output.trajectory_interval=1e-6 \
  --out "$out/energy_fig3" >/dev/null
"$cli" run $S --set davis.stokes=2 --set davis.capillary=0.01 \
  --set output.trajectory_interval=1e-6 --out "$out/energy_deepwell" >/dev/null
snap srs2 --set davis.n_spheres=2 --set davis.stokes=1.2 --set davis.capillary=0 \
  --set davis.angle_deg=60 --set davis.t_star_end=50

echo "-- e_ij,w vs St_n: three spheres, two spheres oblique (30 deg) and head-on"
st three
st two_oblique --set davis.n_spheres=2
st two_headon --set davis.n_spheres=2 --set davis.angle_deg=0
st three_headon --set davis.angle_deg=0
st two_headon_nocap --set davis.n_spheres=2 --set davis.angle_deg=0 --set davis.capillary=0 \
  --set pairwise.rtol=1e-11
echo "-- resting-contact threshold: rest_speed_ratio 1e-4 instead of 1e-3"
st three_rest1e-4 --set pairwise.rest_speed_ratio=1e-4

echo "-- capillary number"
for ca in 0 100 30; do st ca_$ca --set davis.capillary=$ca; done
echo "-- impact angle: curves and the St_n x angle outcome map"
for a in 0 15 45 60; do st angle_$a --set davis.angle_deg=$a; done
"$cli" map $S --param davis.stokes --values 0.5:30:40 --param2 davis.angle_deg \
  --values2 0:80:33 --out "$out/map_st_angle.csv"
echo "-- film thickness h_a, minimum separation h_m, friction"
for ha in 0.005 0.02 0.05; do st film_$ha --set davis.film_ratio=$ha; done
# the same films on the same spheres and liquid: sigma and h_min fixed, so Ca and h_m scale
# as 1/h_a (Ca = 1000 and h_m = 0.01 at h_a = 0.01)
for ha in 0.005 0.02 0.05; do
  ca=$(awk -v h=$ha 'BEGIN { printf "%.6g", 10 / h }')
  hm=$(awk -v h=$ha 'BEGIN { printf "%.6g", 1e-4 / h }')
  st filmphys_$ha --set davis.film_ratio=$ha --set davis.capillary=$ca --set davis.hmin_ratio=$hm
done
for hm in 0.001 0.05; do st hmin_$hm --set davis.hmin_ratio=$hm; done
for mu in 0.1 0.3; do st friction_$mu --set davis.friction=$mu --set davis.restitution=0.9; done
st friction_0 --set davis.friction=0 --set davis.restitution=0.9

/usr/bin/python3 figures/davis_figs.py
