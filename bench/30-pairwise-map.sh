#!/usr/bin/env bash
# Pairwise engine benchmark (Davis 2023 three-sphere collisions): a 40 x 40 map of St_n
# (0.5..30) x impact angle (0..80 deg) with the Table-I defaults of
# examples/scenarios/davis_three.ini (Ca = 1000, h_a = h_m = 0.01, run to t* = 20 or until
# every pair is apart), on 2 threads (OMP_NUM_THREADS=2). Target: < 30 s wall. Prints the wall
# time, collisions per second, the outcome counts, and checks that the rows are identical to a
# 1-thread run of the same map (determinism across thread counts).
# Results in build/bench/pairwise/; docs/performance.md records them.
# Usage: bench/30-pairwise-map.sh PATH_TO_WETDEM_CLI   (from the repository root)
set -euo pipefail
cli=${1:?usage: 30-pairwise-map.sh PATH_TO_WETDEM_CLI}
out=build/bench/pairwise
S=examples/scenarios/davis_three.ini
mkdir -p "$out"
map() { # threads file extra...
  local threads=$1 file=$2
  shift 2
  OMP_NUM_THREADS=$threads "$cli" map $S --param davis.stokes --values 0.5:30:40 \
    --param2 davis.angle_deg "$@" --out "$file"
}
start=$(date +%s.%N)
map 2 "$out/map40x40.csv" --values2 0:80:40
end=$(date +%s.%N)
wall=$(awk -v a="$start" -v b="$end" 'BEGIN { printf "%.2f", b - a }')
runs=$(grep -vc '^#' "$out/map40x40.csv")
runs=$((runs - 1))
echo "40 x 40 map, 2 threads: $runs collisions in $wall s wall ($(awk -v n=$runs -v w=$wall 'BEGIN { printf "%.1f", n / w }') collisions/s)"
grep '^# totals' "$out/map40x40.csv"
echo "outcomes: $(grep -v '^#' "$out/map40x40.csv" | tail -n +2 | cut -d, -f5 | sort | uniq -c | tr -s ' ' | tr '\n' ' ')"
map 1 "$out/map40x40_1thread.csv" --values2 0:80:40
if ! diff -q <(grep -v '^#' "$out/map40x40.csv") <(grep -v '^#' "$out/map40x40_1thread.csv") >/dev/null; then
  echo "FAIL: rows differ between 2 threads and 1 thread"
  exit 1
fi
echo "rows identical with 1 thread"
if awk -v w="$wall" 'BEGIN { exit !(w >= 30) }'; then
  echo "FAIL: $wall s >= 30 s target (machine load: $(cut -d' ' -f1-3 /proc/loadavg))"
  exit 1
fi
