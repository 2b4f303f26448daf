#!/usr/bin/env bash
# The command-line tool when memory runs out. build/tests/wetdem_alloc_fail is the CLI linked
# with the failing allocator of tests/cli_alloc_wrap.c: WETDEM_TEST_FAIL_ALLOC=N fails the N-th
# allocation of the CLI and the library (malloc, calloc, realloc, strdup, and the SUNDIALS and
# GSL constructors the library calls), and the program reports at exit to the file
# WETDEM_TEST_ALLOC_REPORT how many it made, whether the N-th was reached and how many blocks
# are still allocated. Each command below runs once without a failure (it must succeed; its
# output is the reference), then once for each N chosen below, and every run with a failed
# allocation must
#   - exit 1, not by a signal or an abort (GSL's default error handler aborts; the library
#     installs its own around the GSL calls it makes), with "out of memory" on stderr;
#   - free every block it allocated through the wrappers;
#   - leave its --out location absent (or an empty directory), or complete: identical to the
#     reference, with no temporary file. The location is absent before each run. A sweep
#     records a point that failed and goes on: its table may differ from the reference in the
#     rows of points whose status is WETDEM_ERR_NOMEM (and the totals). A many-particle run
#     streams frames and CSV rows while it runs: it may stop with those of the steps it
#     finished, each whole, the indexes naming exactly the frames present (stream_whole).
# OMP_NUM_THREADS=1 keeps the allocation order, and so N, the same from run to run.
#
# Which N: every one up to ALL_UPTO and every one of the last TAIL (where the results are
# written), every STRIDE-th between them. Every command but `fit` makes fewer than ALL_UPTO
# allocations (at most some 140) and is tried at every N. The fit (some 760 allocations,
# 28 ms a run) repeats one evaluation of the model (two verlet collisions, some 50
# allocations) for each iteration and Jacobian column: the set-up and the first evaluations
# are tried at every N, the repeats in between at a stride prime to their period, so that the
# sample still falls on different allocations of an evaluation; the whole test stays near
# 10 s (ASan: about three times that). WETDEM_ALLOC_ALL=1 tries every N of every command (some
# 450 runs more); WETDEM_ALLOC_VERBOSE=1 prints the counts.
#
# Limits: allocations inside the shared libraries (SUNDIALS, GSL, inih, OpenMP, libc's stdio,
# getline, open_memstream and directory streams) do not pass through the wrappers, only the
# constructors of SUNDIALS and GSL objects that the library calls; a failure inside one of
# them (inih reading the scenario, GSL's solver inside the fit, CVODE's own vectors) is not
# reached here. The blocks counted are those allocated through the wrappers.
set -u
here=$(cd "$(dirname "$0")/.." && pwd)
cli=${WETDEM_CLI_ALLOC_FAIL:-$here/${WETDEM_BUILD:-build}/tests/wetdem_alloc_fail}
[ -x "$cli" ] || { echo "test_cli_alloc_failure: $cli not built (make test builds it)"; exit 1; }
export OMP_NUM_THREADS=1
unset WETDEM_TEST_FAIL_ALLOC
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cd "$here" || exit 1
ALL_UPTO=160
TAIL=100
STRIDE=11
fails=0
runs=0
fail() {
  echo "FAIL: $*"
  fails=$((fails + 1))
}

# The N to try for a command that made `total` allocations, one per line.
indices() {
  local total=$1 n
  for ((n = 1; n <= total; n++)); do
    if [ -n "${WETDEM_ALLOC_ALL:-}" ] || [ $n -le $ALL_UPTO ] || [ $n -gt $((total - TAIL)) ] \
      || [ $((n % STRIDE)) -eq 0 ]; then
      echo $n
    fi
  done
}

# Runs the CLI with allocation $1 failed (0: none) and the remaining arguments; sets rc,
# n_alloc, reached and live from its report; stdout and stderr in $work/stdout, $work/stderr.
run_cli() {
  local n=$1
  shift
  rm -f "$work/report"
  WETDEM_TEST_FAIL_ALLOC=$n WETDEM_TEST_ALLOC_REPORT="$work/report" "$cli" "$@" \
    >"$work/stdout" 2>"$work/stderr"
  rc=$?
  runs=$((runs + 1))
  n_alloc=-1 reached=0 live=-1
  [ -f "$work/report" ] && read -r _ n_alloc _ reached _ live <"$work/report"
}

# Whether the sweep table $2 is the reference $1 but for points whose status is
# WETDEM_ERR_NOMEM (a sweep records a point that failed and goes on) and the totals line.
table_whole() {
  awk -F, 'NR == FNR { ref[FNR] = $0; key[FNR] = $1; n = FNR; next }
    { m = FNR }
    $0 != ref[FNR] && !($2 == "WETDEM_ERR_NOMEM" && $1 == key[FNR]) && !/^# totals/ { bad = 1 }
    END { exit bad || m != n }' "$1" "$2"
}

# Whether the --out directory $2 of a many-particle run is what the reference run $1 wrote
# up to some step: no temporary file; every file identical to the reference's, except the
# CSV, a prefix of whole rows of the reference's, and the series indexes, naming exactly
# the frames present.
stream_whole() {
  local ref=$1 out=$2 f name listed present
  [ -z "$(find "$out" -name '.*' -o -name '*.tmp*')" ] || return 1
  for f in "$out"/*; do
    name=${f##*/}
    cmp -s "$f" "$ref/$name" && continue
    case $name in
      *.csv)
        [ -f "$ref/$name" ] && [ "$(tail -c 1 "$f" | od -An -c | tr -d ' ')" = '\n' ] \
          && head -c "$(stat -c %s "$f")" "$ref/$name" | cmp -s - "$f" || return 1 ;;
      *.vtk.series)
        listed=$(sed -n 's/.*"name" : "\([^"]*\)".*/\1/p' "$f" | sort)
        present=$(cd "$out" && ls "${name%.vtk.series}"_[0-9]*.vtk 2>/dev/null | sort)
        [ -n "$listed" ] && [ "$listed" = "$present" ] || return 1 ;;
      *) return 1 ;;
    esac
  done
}

# check NAME KIND OUT ARGS...: the command ARGS whose --out location is OUT ("" for none),
# written as KIND: "set", files whole all together or none; "table", a sweep's table
# (table_whole); "stream", a many-particle run's directory (stream_whole).
check() {
  local name=$1 kind=$2 out=$3
  shift 3
  rm -rf "$out" "$work/ref"
  run_cli 0 "$@"
  if [ $rc -ne 0 ] || [ "$n_alloc" -lt 0 ]; then
    fail "$name: without a failure: exit $rc, $n_alloc allocations: $(head -c 300 "$work/stderr")"
    return
  fi
  local total=$n_alloc
  [ "$live" = 0 ] || fail "$name: without a failure: $live blocks not freed at exit"
  [ -n "$out" ] && cp -R "$out" "$work/ref"
  local n tried=0
  for n in $(indices "$total"); do
    rm -rf "$out"
    run_cli "$n" "$@"
    tried=$((tried + 1))
    local at="$name, allocation $n of $total failed"
    if [ "$reached" != 1 ]; then
      fail "$at: not reached (exit $rc, $n_alloc allocations; the count is not deterministic)"
      continue
    fi
    [ "$live" = 0 ] || fail "$at: $live blocks not freed at exit"
    if [ $rc -ne 1 ]; then
      fail "$at: exit $rc, expected 1: $(head -c 300 "$work/stderr")"
    elif ! grep -q 'out of memory' "$work/stderr"; then
      fail "$at: stderr does not say 'out of memory': $(head -c 300 "$work/stderr")"
    fi
    if [ -n "$out" ] && [ -e "$out" ]; then
      if [ -d "$out" ] && [ -z "$(ls -A "$out")" ]; then
        :
      elif ! diff -r "$work/ref" "$out" >"$work/diff" 2>&1 \
        && ! { [ "$kind" = table ] && table_whole "$work/ref" "$out"; } \
        && ! { [ "$kind" = stream ] && stream_whole "$work/ref" "$out"; }; then
        fail "$at: $out is neither absent nor complete: $(head -c 400 "$work/diff")"
      fi
    fi
  done
  [ -n "${WETDEM_ALLOC_VERBOSE:-}" ] && echo "$name: $total allocations, $tried tried"
}

o=$work/out
sc=examples/scenarios
check run_pairwise set "$o/pair" run $sc/nijssen_head_on.ini --set collision.stokes=10 --out "$o/pair"
check run_json set "" run $sc/nijssen_head_on.ini --set collision.stokes=10 --json
check run_verlet set "$o/dry" run $sc/dry_hertz.ini --out "$o/dry"
check run_many stream "$o/many" run $sc/many_settling.ini --set insert.count=8 --set run.t_end=1e-3 \
  --out "$o/many"
check sweep table "$o/sweep.csv" sweep $sc/dry_hertz.ini --param collision.speed --values 0.1:0.5:3 \
  --out "$o/sweep.csv"
check describe set "" describe nijssen
check forces set "" forces --model reynolds --gaps 1e-7:1e-3:5
check track set "$o/frames.csv" track examples/tracks/punch_45deg.csv --fps 5000 \
  --pixel-size 0.000175 --frames "$o/frames.csv" --json

# A fit of a dry restitution to two points: verlet collisions, the cheapest fit.
cat >"$work/dry.ini" <<'EOF'
[collision]
striker = ball
target = sphere
initial_gap = 1e-4
t_end = 1e-2
[material.ball]
preset = steel1
[fluid]
preset = water
viscosity = 1e-3
[models]
force = hertz
[integrator]
name = verlet
EOF
printf 'stokes_n,e_n\n2000,0.8\n8000,0.75\n' >"$work/dry.csv"
check fit set "$o/fit" fit "$work/dry.ini" --data "$work/dry.csv" --fit material.ball.restitution \
  --init 0.7 --out "$o/fit/fit.csv" --curve "$o/fit/curve.csv" --curve-points 2

[ $fails -eq 0 ] && echo "test_cli_alloc_failure: ok ($runs runs)" \
  || { echo "test_cli_alloc_failure: $fails failure(s) in $runs runs"; exit 1; }
