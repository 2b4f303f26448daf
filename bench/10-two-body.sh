#!/usr/bin/env bash
# Two-body benchmark (issue: soft engine): the Nijssen 2023 Fig. 3 sweep — 4 materials x 100
# Stokes numbers from 10 to 3000 (log), head-on, Delrin/glass/steel in water — with the adaptive
# integrator (cvode with its default method, auto; and with bdf for comparison) against
# velocity Verlet at dt = 2 % of the Hertz contact time (Nijssen's choice), all on one core
# (OMP_NUM_THREADS=1), in the same run.
#
# Verlet runs on a documented subset: every 3rd Stokes number of the sweep (34 per material,
# `--values 10:3000:34 --log` hits exactly those values), because one Verlet sweep of all 400
# collisions takes ~5 CPU minutes; cvode runs on the same subset as well, so the ratios of
# force evaluations and of CPU time compare the same 136 collisions. The report also gives
# Verlet's full-sweep cost estimated as the subset's x 100/34 (the subset samples the log-spaced
# sweep uniformly), clearly marked as an estimate.
#
# Time: CPU time (user + sys of each wetdem process, /usr/bin/time) and wall time (the sweeps'
# own `# totals:` clock); force evaluations are exact counts (wetdem_sim_stats).
# Accuracy: on every 9th Stokes number (12 per material) a very fine reference (cvode rtol
# 1e-12, itself checked against Verlet at dt = 0.2 % of the Hertz time at St = 100, 548, 3000)
# gives the converged e; every production sweep must be within 0.5 % of it
# (bench/two_body_report.py checks and prints all of this, and exits 1 if a target fails).
# Results in build/bench/two_body/; docs/performance.md records them. About 3 minutes.
# Usage: bench/10-two-body.sh PATH_TO_WETDEM_CLI   (from the repository root)
set -euo pipefail
cli=${1:?usage: 10-two-body.sh PATH_TO_WETDEM_CLI}
out=build/bench/two_body
S=examples/scenarios/nijssen_head_on.ini
mkdir -p "$out"
export OMP_NUM_THREADS=1
[[ -x /usr/bin/time ]] || { echo "10-two-body.sh: needs /usr/bin/time (package time)" >&2; exit 1; }

# sweep LABEL VALUES [--set ...]: the four materials; CPU "user sys wall" per process appended
# to LABEL.cpu
sweep() {
  local label=$1 values=$2
  shift 2
  : > "$out/$label.cpu"
  for m in steel1 steel2 glass delrin; do
    /usr/bin/time -a -o "$out/$label.cpu" -f "%U %S %e" \
      "$cli" sweep $S --set collision.striker=$m "$@" --param collision.stokes \
      --values "$values" --log --out "$out/${label}_$m.csv"
  done
}

# t_end_crossings = 5 (t_end = 5 R*/v_n instead of 20) and St from 10: a collision that sticks
# runs to t_end, and at St < 10 one Verlet run at 2 % of the Hertz time takes 10^8 steps and
# more (docs/performance.md); every sweep gets the same set-up.
common=(--set collision.t_end_crossings=5)
echo "adaptive sweeps: cvode (default method auto) and cvode bdf, 4 x 100 collisions each"
sweep cvode 10:3000:100 "${common[@]}" --set integrator.name=cvode
sweep cvode_bdf 10:3000:100 "${common[@]}" --set integrator.name=cvode \
  --set integrator.method=bdf
echo "subset (every 3rd St, 4 x 34 collisions): verlet at 2 % of the Hertz time, and cvode"
sweep verlet_sub 10:3000:34 "${common[@]}" --set integrator.name=verlet \
  --set integrator.dt_fraction=0.02
sweep cvode_sub 10:3000:34 "${common[@]}" --set integrator.name=cvode
echo "converged reference on the subset 10:3000:12 (every 9th Stokes number of the sweep)"
sweep ref_cvode 10:3000:12 "${common[@]}" --set integrator.name=cvode \
  --set integrator.rtol=1e-12 --set integrator.atol=1e-13
echo "check of the reference: cvode rtol 1e-12 vs Verlet at 0.2 % of the Hertz time, St 100..3000"
sweep check_cvode 100:3000:3 "${common[@]}" --set integrator.name=cvode \
  --set integrator.rtol=1e-12 --set integrator.atol=1e-13
sweep check_verlet 100:3000:3 "${common[@]}" --set integrator.name=verlet \
  --set integrator.dt_fraction=0.002
/usr/bin/python3 bench/two_body_report.py "$out"
