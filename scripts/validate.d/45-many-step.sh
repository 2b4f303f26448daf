#!/usr/bin/env bash
# The many-particle step against the viscous relaxation time (docs/many.md, Time step): two
# spheres in a constant viscous damping (Reynolds lubrication held at h_min = 10 um, gap 5 um,
# 1 Pa s) approach at 0.1 m/s, and their approach speed decays as exp(-t/tau),
# tau = m*/c_d = 11.1 us. The pair is run for 4 tau at steps from 0.02 to 0.95 tau. A step of
# tau must be refused (exit 2); the steps above about 0.6 tau may fail their energy budget
# (exit 1, files kept). figures/many_step.py checks the decay against the scheme's map and
# the budget's second order, and draws docs/figures/many_step_bound.png.
# Usage: scripts/validate.d/45-many-step.sh PATH_TO_WETDEM_CLI   (from the repository root)
set -euo pipefail
. scripts/piece-start.sh
piece_start 45-many-step.sh out/validate/many_step "$@"
export OMP_NUM_THREADS=1

cat >"$out/pair.ini" <<'EOF'
# Two glass-like spheres (R = 1 mm) at a 5 um gap, inside h_min = 10 um of Reynolds
# lubrication in a 1 Pa s liquid, approaching at 0.1 m/s (scripts/validate.d/45-many-step.sh).
[box]
size_x = 10e-3
size_y = 10e-3
size_z = 10e-3
[walls]
faces = none
[material.glass]
density = 2500
youngs_modulus = 70e9
poisson_ratio = 0.22
restitution = 0.9
[fluid]
viscosity = 1
[models]
force = reynolds
min_separation = fixed
[model.fixed]
h_min = 10e-6
[particle.a]
material = glass
radius = 1e-3
x = 3.9975e-3
y = 5e-3
z = 5e-3
vx = 0.05
[particle.b]
material = glass
radius = 1e-3
x = 6.0025e-3
y = 5e-3
z = 5e-3
vx = -0.05
[run]
steps = 1
[dump]
vtk_every = 0
csv_every = 1
EOF

tau=$("$cli" run "$out/pair.ini" --check --json |
  /usr/bin/python3 -c 'import json, sys; print(repr(json.load(sys.stdin)["relaxation_time_s"]))')
echo "-- relaxation time tau = $tau s; runs of 4 tau at dt / tau ="
echo "$tau" >"$out/tau.txt"
for lam in 0.02 0.05 0.1 0.15 0.2 0.25 0.3 0.4 0.5 0.6 0.7 0.8 0.9 0.95; do
  read -r dt steps < <(/usr/bin/python3 -c \
    "import math; print(repr($lam * $tau), math.ceil(4 / $lam - 1e-9))")
  rc=0
  "$cli" run "$out/pair.ini" --set run.dt="$dt" --set run.steps="$steps" \
    --out "$out/lambda_$lam" >"$out/lambda_$lam.log" 2>&1 || rc=$?
  echo "   $lam: $steps steps, exit $rc"
  if [ "$rc" -gt 1 ]; then
    cat "$out/lambda_$lam.log"
    exit 1
  fi
done
rc=0
"$cli" run "$out/pair.ini" --set run.dt="$tau" --check >"$out/refused.log" 2>&1 || rc=$?
if [ "$rc" -ne 2 ] || ! grep -q "viscous relaxation time" "$out/refused.log"; then
  echo "  [FAIL] a step of tau was not refused with exit 2 (exit $rc)"
  cat "$out/refused.log"
  exit 1
fi
echo "  [ok] a step of tau is refused (exit 2): $(sed 's/^.*many: //' "$out/refused.log" | cut -c1-90)..."
/usr/bin/python3 figures/many_step.py --dir "$out"
