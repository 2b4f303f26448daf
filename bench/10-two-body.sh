#!/usr/bin/env bash
# Two-body benchmark (issue: soft engine): the Nijssen 2023 Fig. 3 sweep — 4 materials x 100
# Stokes numbers from 10 to 3000, head-on, Delrin/glass/steel in water — with the adaptive
# integrator (cvode, default tolerances) against velocity Verlet at dt = 2 % of the Hertz
# contact time (Nijssen's choice), both on one core (OMP_NUM_THREADS=1), in the same run.
# Prints force evaluations (RHS evaluations, wetdem_sim_stats) and wall time of each and
# their ratios. Accuracy: on a subset (every 9th Stokes number: 12 per material) a very fine
# reference (cvode rtol 1e-12, itself checked against Verlet at dt = 0.2 % of the Hertz time
# at St = 100, 548, 3000) gives the converged e; both production sweeps must be within 0.5 %
# of it (bench/two_body_report.py).
# Results in build/bench/two_body/; docs/performance.md records them.
# Usage: bench/10-two-body.sh PATH_TO_WETDEM_CLI   (from the repository root)
set -euo pipefail
cli=${1:?usage: 10-two-body.sh PATH_TO_WETDEM_CLI}
out=build/bench/two_body
S=examples/scenarios/nijssen_head_on.ini
mkdir -p "$out"
export OMP_NUM_THREADS=1

sweep() { # integrator-label values extra-sets...
  local label=$1 values=$2
  shift 2
  for m in steel1 steel2 glass delrin; do
    "$cli" sweep $S --set collision.striker=$m "$@" --param collision.stokes \
      --values "$values" --log --out "$out/${label}_$m.csv"
  done
}

# t_end_crossings = 5 (t_end = 5 R*/v_n instead of 20) and St from 10: a collision that sticks
# runs to t_end, and at St < 10 one Verlet run at 2 % of the Hertz time takes 10^8 steps and
# more (docs/performance.md); both integrators get the same set-up.
common=(--set collision.t_end_crossings=5)
echo "production sweeps (4 x 100 collisions each, St = 10..3000, one core)"
sweep cvode 10:3000:100 "${common[@]}" --set integrator.name=cvode
sweep verlet 10:3000:100 "${common[@]}" --set integrator.name=verlet \
  --set integrator.dt_fraction=0.02
echo "converged reference on the subset 10:3000:12 (every 9th Stokes number of the sweep)"
sweep ref_cvode 10:3000:12 "${common[@]}" --set integrator.name=cvode \
  --set integrator.rtol=1e-12 --set integrator.atol=1e-13
echo "check of the reference: cvode rtol 1e-12 vs Verlet at 0.2 % of the Hertz time, St 100..3000"
sweep check_cvode 100:3000:3 "${common[@]}" --set integrator.name=cvode \
  --set integrator.rtol=1e-12 --set integrator.atol=1e-13
sweep check_verlet 100:3000:3 "${common[@]}" --set integrator.name=verlet \
  --set integrator.dt_fraction=0.002
/usr/bin/python3 bench/two_body_report.py "$out"
