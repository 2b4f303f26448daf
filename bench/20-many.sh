#!/usr/bin/env bash
# 20-many.sh — many-particle benchmark, wetdem against LIGGGHTS 3.8 on the same system in one
# run: N polydisperse spheres settling in a closed box (bench/many_bench.c describes it), dry
# (Hertz-Mindlin; LIGGGHTS model hertz tangential history) and wet (wetdem sb + capillary;
# LIGGGHTS cohesion easo/capillary/viscous), on 1 and 2 threads (LIGGGHTS: MPI ranks).
#
# Two protocols, each code and variant measured back to back so both see the same machine load:
#  full:  from the lattice, SETTLE untimed steps, then STEPS timed steps (each variant follows
#         its own trajectory: wet spheres cluster, so the wet run ends with many more contacts);
#  same:  from one shared state, the dry run's state after STATE steps (written by wetdem as a
#         LIGGGHTS data file), SAME_STEPS timed steps of every variant (the configurations start
#         equal, but the capillary force gathers the wet spheres within the window: contacts and
#         bridges at the end are printed);
#  frozen: the same state, FROZEN_STEPS timed steps of dt = FROZEN_DT (1e-9 s: the spheres move
#         by < 1e-9 m, so every variant evaluates the same configuration at every step); the
#         like-for-like measure of the cost of the wet models.
# Each measurement is REPEAT rounds of the wetdem run followed at once by its LIGGGHTS run; the
# best of the rounds is kept. Reports particle-steps per second (wall clock of the timed steps),
# per CPU-second on 1 thread (user + system time of the timed steps; for LIGGGHTS the CPU time of
# a run without timed steps is subtracted; on a virtual machine whose cores are also taken by
# other guests, CPU time leaves out the time the host took away, and wall time does not), memory
# per particle ((max RSS - RSS of a 1-particle run) / N) and the ratios against the targets:
# >= 2x LIGGGHTS per core dry and wet, >= 1.8x speed-up on 2 threads, wet <= 1.3x dry.
# With the frozen protocol, the floor of the wet cost: bench/bridge_floor.c's bare loop over the
# same state's bridges apart (their sb and capillary forces onto both spheres, nothing else),
# best of REPEAT rounds of FROZEN_STEPS steps, and the wet / dry cost it alone would add to the
# dry run. Then, with valgrind, the load-independent measure: instructions per particle-step of
# both codes on the shared state (same-state and frozen protocols, callgrind, one thread), and
# the floor's instructions per bridge apart.
#
# After the three protocols, the frozen protocol's wet / dry cost for each film thickness of
# FILMS (wetdem, one thread): the cost against the number of pairs within the films.
# Then (before the floor), PAIRS pairs of a one-thread and a two-thread
# run back to back per protocol and variant (LIGGGHTS: the frozen protocol), each pair's
# speed-up and their median: a measure of the two-thread speed-up that a host whose speed
# drifts between runs spoils less than the best of runs taken minutes apart; and PAIRS pairs of
# a frozen dry and wet run on one thread back to back, the same for the wet / dry cost.
#
# Usage: bench/20-many.sh [WETDEM_CLI]    (make bench passes the CLI; it is not needed here)
# Environment: N (20000), SETTLE (500), STEPS (1500), STATE (3000), SAME_STEPS (300),
# FROZEN_STEPS (300), FROZEN_DT (1e-9), REPEAT (3), FILMS ("3.2e-6 10e-6 20e-6"; "" skips the
# film sweep), PAIRS (5; 0 skips the pairs), INSTR_STEPS
# (100; 0 skips the instruction counts) — about 12-22 minutes on 2 cores;
# OMP_WAIT_POLICY and GOMP_SPINCOUNT (default: GOMP_SPINCOUNT=20000, a waiting thread spins
# briefly, about a step's time, then sleeps; fully active threads collapse when the host takes
# a core, fully passive ones pay a wake-up at every parallel region, 5-8 % on 2 threads here).
# Results go to build/bench/many/ (logs, results.txt, summary.txt, the figure many_bench.png:
# bench/many_figure.py). The ratios are printed, not
# enforced: the machine may be shared, which the load average printed with the results shows.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
cd "$root"
N=${N:-20000}
SETTLE=${SETTLE:-500}
STEPS=${STEPS:-1500}
STATE=${STATE:-3000}
SAME_STEPS=${SAME_STEPS:-300}
FROZEN_STEPS=${FROZEN_STEPS:-300}
FROZEN_DT=${FROZEN_DT:-1e-9}
REPEAT=${REPEAT:-3}
INSTR_STEPS=${INSTR_STEPS:-100}
out=build/bench/many
mkdir -p "$out"
res="$out/results.txt"
: > "$res"
: > "$out/wetdem.log"
: > "$out/liggghts.log"

cc -std=c11 -D_DEFAULT_SOURCE -O2 -fopenmp -Iinclude bench/many_bench.c build/libwetdem.a \
   -lsundials_cvode -lsundials_nvecserial -lgsl -lgslcblas -linih -lm -o "$out/many_bench"
cc -std=c11 -D_DEFAULT_SOURCE -O2 bench/bridge_floor.c -lm -o "$out/bridge_floor"
"$out/many_bench" --n "$N" --data "$out/system.data"
"$out/many_bench" --n 1 --data "$out/one.data"

field() { sed -n "s/.*$1=\([^ ]*\).*/\1/p"; }
# CPU time the host took from this virtual machine so far (steal, all cores) [s]
steal_s() { awk -v hz="$(getconf CLK_TCK)" '/^cpu /{printf "%.2f", $9 / hz}' /proc/stat; }
steal0=$(steal_s)
if [ -z "${OMP_WAIT_POLICY:-}" ] && [ -z "${GOMP_SPINCOUNT:-}" ]; then
  export GOMP_SPINCOUNT=20000
fi
have_lg=false
command -v liggghts >/dev/null && command -v mpirun >/dev/null && have_lg=true
deck=$root/bench/liggghts

# wetdem run: protocol variant threads steps [many_bench args] -> "rate kb psteps_per_cpu_s
# contacts bridges kick_s forces_s" (the last two: wall time of the timed steps' kicks and
# drifts, and of their force passes)
run_wd() {
  local proto=$1 variant=$2 t=$3 steps=$4 flag=""
  shift 4
  [ "$variant" = wet ] && flag="--wet"
  local line
  line=$(OMP_NUM_THREADS=$t OMP_PROC_BIND=false "$out/many_bench" $flag "$@")
  echo "$proto $line" >> "$out/wetdem.log"
  echo "$(echo "$line" | field psteps_per_s) $(echo "$line" | field maxrss_kb)" \
       "$(awk -v n="$N" -v s="$steps" -v c="$(echo "$line" | field cpu_seconds)" \
          'BEGIN{printf "%.4g", (c > 0 ? n * s / c : 0)}')" \
       "$(echo "$line" | field contacts) $(echo "$line" | field bridges)" \
       "$(echo "$line" | field kick_s) $(echo "$line" | field forces_s)"
}

# LIGGGHTS run: variant ranks data nsettle nsteps dt -> "rate kb cpu_seconds"
run_lg() {
  local log="$out/liggghts_$1_$2_$4.log"
  /usr/bin/time -f "maxrss_kb=%M cpu=%U+%S" -o "$out/time_$1_$2.txt" \
    mpirun --allow-run-as-root --oversubscribe -np "$2" liggghts -in "$deck/$1.in" \
    -var deckdir "$deck" -var data "$3" -var nsettle "$4" -var nsteps "$5" \
    -var dt "$6" -log "$log" -screen none -nocite
  local secs kb cpu # the second "Loop time" line is the timed run
  secs=$(grep "^Loop time" "$log" | sed -n 2p | awk '{print $4}')
  kb=$(field maxrss_kb < "$out/time_$1_$2.txt")
  cpu=$(field cpu < "$out/time_$1_$2.txt" | bc -l)
  echo "$(awk -v n="$N" -v s="$5" -v t="$secs" 'BEGIN{printf "%.4g", n*s/t}') $kb $cpu"
}

# One measurement, REPEAT rounds of wetdem then LIGGGHTS back to back (so both see about the
# same load); the best rate and the best rate per CPU-second of each code are kept (a shared
# machine only ever slows a run down). LIGGGHTS' CPU time of the timed steps on 1 rank is its
# run's minus that of a run without timed steps (start-up, reading the data, settling).
# Arguments: protocol variant threads data nsettle nsteps dt [many_bench args]
measure() {
  local proto=$1 variant=$2 t=$3 data=$4 nsettle=$5 nsteps=$6 dt=$7
  shift 7
  local wbest="0 0 0 - - 0 0" lbest="0 0 0" c0=0 rep
  if $have_lg && [ "$t" = 1 ]; then
    c0=$(run_lg "$variant" 1 "$data" "$nsettle" 0 "$dt" | awk '{print $3}')
  fi
  for rep in $(seq "$REPEAT"); do
    local w l
    w=$(run_wd "$proto" "$variant" "$t" "$nsteps" --dt "$dt" "$@")
    wbest=$(printf '%s\n%s\n' "$wbest" "$w" | awk 'NR == 1 {r = $1; k = $2; c = $3; x = $4; y = $5
        a = $6; b = $7}
      NR == 2 {if ($1 > r) {r = $1; k = $2; x = $4; y = $5; a = $6; b = $7}; if ($3 > c) c = $3}
      END {print r, k, c, x, y, a, b}')
    $have_lg || continue
    l=$(run_lg "$variant" "$t" "$data" "$nsettle" "$nsteps" "$dt" | awk -v c0="$c0" -v t="$t" \
        -v n="$N" -v s="$nsteps" '{print $1, $2, (t == 1 && $3 > c0) ? n * s / ($3 - c0) : 0}')
    echo "$proto liggghts $variant $t $l" >> "$out/liggghts.log"
    lbest=$(printf '%s\n%s\n' "$lbest" "$l" | awk 'NR == 1 {r = $1; k = $2; c = $3}
      NR == 2 {if ($1 > r) {r = $1; k = $2}; if ($3 > c) c = $3}
      END {print r, k, c}')
  done
  echo "$proto wetdem $variant $t $wbest" | tee -a "$res" >&2
  $have_lg && echo "$proto liggghts $variant $t $lbest - -" | tee -a "$res" >&2
  return 0
}

lg_base=0
$have_lg && lg_base=$(run_lg dry 1 "$out/one.data" 0 1 1e-5 | awk '{print $2}')
base_kb=$(OMP_NUM_THREADS=1 "$out/many_bench" --n 1 --settle 1 --steps 1 | field maxrss_kb)

# ---- full protocol ----
for variant in dry wet; do
  for t in 1 2; do
    measure full "$variant" "$t" "$out/system.data" "$SETTLE" "$STEPS" 1e-5 \
      --n "$N" --settle "$SETTLE" --steps "$STEPS"
  done
done

# ---- same-state and frozen-configuration protocols ----
OMP_NUM_THREADS=2 "$out/many_bench" --n "$N" --settle "$STATE" --steps 0 \
  --state-out "$out/state.data" > /dev/null
for variant in dry wet; do
  for t in 1 2; do
    measure same "$variant" "$t" "$out/state.data" 0 "$SAME_STEPS" 1e-5 \
      --state-in "$out/state.data" --settle 0 --steps "$SAME_STEPS"
  done
done
for variant in dry wet; do
  for t in 1 2; do
    measure frozen "$variant" "$t" "$out/state.data" 0 "$FROZEN_STEPS" "$FROZEN_DT" \
      --state-in "$out/state.data" --settle 0 --steps "$FROZEN_STEPS"
  done
done
# ---- the wet cost against the film thickness ----
# The frozen protocol's wet / dry cost for each film thickness of FILMS (per sphere [m]; the
# benchmark's wet variant has 20e-6): REPEAT rounds, each a dry run and then a wet run per film,
# back to back on one thread; the best of each -> "film M wet_rate dry_rate contacts bridges".
# More film, more pairs within the films (bridges apart) besides the same contacts: the cost
# against that number, and where the target holds (many_bench.c: 3 delta / R of liquid).
FILMS=${FILMS-"3.2e-6 10e-6 20e-6"}
if [ -n "$FILMS" ]; then
  film_dry=0
  declare -A film_wet film_line
  for rep in $(seq "$REPEAT"); do
    r=$(run_wd film dry 1 "$FROZEN_STEPS" --dt "$FROZEN_DT" --state-in "$out/state.data" \
        --settle 0 --steps "$FROZEN_STEPS" | awk '{print $1}')
    film_dry=$(awk -v a="$film_dry" -v b="$r" 'BEGIN{print (b > a) ? b : a}')
    for f in $FILMS; do
      line=$(run_wd film wet 1 "$FROZEN_STEPS" --dt "$FROZEN_DT" --state-in "$out/state.data" \
             --settle 0 --steps "$FROZEN_STEPS" --film "$f")
      r=$(echo "$line" | awk '{print $1}')
      if awk -v a="${film_wet[$f]:-0}" -v b="$r" 'BEGIN{exit !(b > a)}'; then
        film_wet[$f]=$r
        film_line[$f]=$(echo "$line" | awk '{print $4, $5}')
      fi
    done
  done
  for f in $FILMS; do
    echo "film $f ${film_wet[$f]} $film_dry ${film_line[$f]}" | tee -a "$res" >&2
  done
fi
# ---- paired two-thread speed-ups ----
# PAIRS pairs of runs, each pair a one-thread and a two-thread run back to back (every other
# pair in the other order, so that a drift of the host's speed favours neither side): each
# pair's speed-up, and their median, least and largest. The best-of-REPEAT speed-ups above
# compare the best one-thread run with the best two-thread run, taken minutes apart; on a host
# whose speed moves by up to 2x between consecutive runs (and whose one-thread runs are at
# times much faster than their neighbours) the two runs of a pair see about the same load.
# wetdem in every protocol, LIGGGHTS (1 and 2 ranks) in the frozen one.
# Arguments: protocol variant code data nsettle nsteps dt [many_bench args] -> "pair ..." line
paired() {
  local proto=$1 variant=$2 code=$3 data=$4 nsettle=$5 nsteps=$6 dt=$7 k t one two
  shift 7
  local ratios=()
  for k in $(seq "$PAIRS"); do
    one=0 two=0
    for t in $( ((k % 2)) && echo 1 2 || echo 2 1); do
      local rate
      if [ "$code" = wetdem ]; then
        rate=$(run_wd "$proto" "$variant" "$t" "$nsteps" --dt "$dt" "$@" | awk '{print $1}')
      else
        rate=$(run_lg "$variant" "$t" "$data" "$nsettle" "$nsteps" "$dt" | awk '{print $1}')
      fi
      if [ "$t" = 1 ]; then one=$rate; else two=$rate; fi
    done
    ratios+=("$(awk -v a="$one" -v b="$two" 'BEGIN{printf "%.3f", (a > 0 ? b / a : 0)}')")
  done
  echo "pair $proto $code $variant ${ratios[*]}" | tee -a "$res" >&2
}
# The same for the frozen protocol's wet / dry cost on one thread: PAIRS pairs of a dry and a
# wet run back to back (every other pair in the other order) -> "costpair frozen r1 r2 ..."
# (each dry rate over its wet rate). The best-of-REPEAT cost above compares runs taken minutes
# apart, between LIGGGHTS runs; a pair's two runs see about the same machine.
paired_cost() {
  local k v dry wet ratios=()
  for k in $(seq "$PAIRS"); do
    for v in $( ((k % 2)) && echo dry wet || echo wet dry); do
      local rate
      rate=$(run_wd frozen "$v" 1 "$FROZEN_STEPS" --dt "$FROZEN_DT" --state-in \
             "$out/state.data" --settle 0 --steps "$FROZEN_STEPS" | awk '{print $1}')
      if [ "$v" = dry ]; then dry=$rate; else wet=$rate; fi
    done
    ratios+=("$(awk -v a="$dry" -v b="$wet" 'BEGIN{printf "%.3f", (b > 0 ? a / b : 0)}')")
  done
  echo "costpair frozen ${ratios[*]}" | tee -a "$res" >&2
}
PAIRS=${PAIRS:-5}
if [ "$PAIRS" -gt 0 ]; then
  paired_cost
  for variant in dry wet; do
    paired full "$variant" wetdem "$out/system.data" "$SETTLE" "$STEPS" 1e-5 \
      --n "$N" --settle "$SETTLE" --steps "$STEPS"
    paired same "$variant" wetdem "$out/state.data" 0 "$SAME_STEPS" 1e-5 \
      --state-in "$out/state.data" --settle 0 --steps "$SAME_STEPS"
    paired frozen "$variant" wetdem "$out/state.data" 0 "$FROZEN_STEPS" "$FROZEN_DT" \
      --state-in "$out/state.data" --settle 0 --steps "$FROZEN_STEPS"
    $have_lg && paired frozen "$variant" liggghts "$out/state.data" 0 "$FROZEN_STEPS" \
      "$FROZEN_DT"
  done
fi

# the floor: the bare loop over the bridges apart of the same state (bench/bridge_floor.c),
# best of REPEAT rounds of FROZEN_STEPS steps -> "floor bridges_apart scalar_ns vector_ns
# gather_ns" (0 for a version the processor lacks)
"$out/bridge_floor" --state-in "$out/state.data" --steps "$FROZEN_STEPS" --repeat "$REPEAT" |
  awk '{for (k = 2; k <= NF; k++) {split($k, a, "="); v[a[1]] = a[2]}
        print "floor", v["bridges_apart"], v["scalar_ns"], v["vector_ns"], v["gather_ns"] + 0}' |
  tee -a "$res" >&2
$have_lg || echo "20-many: liggghts or mpirun not installed: LIGGGHTS half skipped" \
  "(scripts/install-deps bench)"

# ---- instruction counts (load-independent) ----
# Instructions per particle-step of each code and variant on the shared state, same-state
# (dt 1e-5) and frozen (FROZEN_DT) protocols, one thread / one rank without mpirun, under
# callgrind: a run of INSTR_STEPS steps minus a run of 0 steps (start-up, reading the state).
# Arguments: code variant dt steps -> instructions of the whole run
count_instr() {
  local flag="" vg=(valgrind --tool=callgrind --callgrind-out-file=/dev/null)
  [ "$2" = wet ] && flag="--wet"
  if [ "$1" = wetdem ]; then
    OMP_NUM_THREADS=1 "${vg[@]}" "$out/many_bench" $flag --state-in "$out/state.data" \
      --settle 0 --steps "$4" --dt "$3" 2>&1 >/dev/null | sed -n 's/.*Collected : //p'
  else
    "${vg[@]}" liggghts -in "$deck/$2.in" -var deckdir "$deck" -var data "$out/state.data" \
      -var nsettle 0 -var nsteps "$4" -var dt "$3" -log "$out/liggghts_instr.log" \
      -screen none -nocite 2>&1 | sed -n 's/.*Collected : //p'
  fi
}
if [ "$INSTR_STEPS" -gt 0 ] && command -v valgrind >/dev/null; then
  for variant in dry wet; do
    for code in wetdem liggghts; do
      [ "$code" = liggghts ] && ! command -v liggghts >/dev/null && continue
      base=$(count_instr "$code" "$variant" 1e-5 0)
      for proto in same frozen; do
        dt=1e-5
        [ "$proto" = frozen ] && dt=$FROZEN_DT
        total=$(count_instr "$code" "$variant" "$dt" "$INSTR_STEPS")
        echo "instr $proto $code $variant $(( (total - base) / (N * INSTR_STEPS) ))" |
          tee -a "$res" >&2
      done
    done
  done
  fl=()
  for s in 0 "$INSTR_STEPS"; do # the floor's, per bridge apart (its fastest version)
    fl+=("$(valgrind --tool=callgrind --callgrind-out-file=/dev/null "$out/bridge_floor" \
      --state-in "$out/state.data" --steps "$s" --repeat 1 --kernel vector 2>&1 |
      sed -n 's/.*Collected : //p')")
  done
  nb=$(awk '/^floor /{print $2}' "$res")
  [ "${nb:-0}" -gt 0 ] && echo "instr floor $(( (fl[1] - fl[0]) / (nb * INSTR_STEPS) ))" |
    tee -a "$res" >&2
else
  echo "20-many: valgrind not installed or INSTR_STEPS=0: instruction counts skipped" >&2
fi

# ---- report ----
# the processor, as the kernel reports it (a virtual machine's host may change between runs)
echo "processor: $(sed -n 's/^model name[[:space:]]*: //p' /proc/cpuinfo | sort -u | head -n 1)," \
     "second-level cache $(getconf LEVEL2_CACHE_SIZE 2>/dev/null || echo '?') bytes," \
     "AVX-512 $(grep -qw avx512f /proc/cpuinfo && echo yes || echo no)" | tee -a "$res"
echo "load average after the run: $(cut -d' ' -f1-3 /proc/loadavg), $(nproc) cores;" \
     "time taken by the host (steal) during the run: $(awk -v a="$steal0" -v b="$(steal_s)" \
     'BEGIN{printf "%.1f", b - a}') s" | tee -a "$res"
awk -v n="$N" -v wb="$base_kb" -v lb="$lg_base" -v steps="$STEPS" -v same="$SAME_STEPS" \
    -v fsteps="$FROZEN_STEPS" -v fdt="$FROZEN_DT" -v isteps="$INSTR_STEPS" '
  /^(full|same|frozen) / { k = $1 " " $2 " " $3 " " $4; rate[k] = $5; kb[k] = $6; cpu[k] = $7
                    con[k] = $8; bri[k] = $9; kick[k] = $10; frc[k] = $11 }
  # the values $first.. of a pair line: their median, range, count and how many reach bound
  # (at or above it with at_least, else at or below)
  function pair_stats(k, first, bound, at_least,   m, f, a, b, x, v) {
    m = 0
    for (f = first; f <= NF; f++) v[++m] = $f
    for (a = 2; a <= m; a++) for (b = a; b > 1 && v[b - 1] > v[b]; b--) {
      x = v[b]; v[b] = v[b - 1]; v[b - 1] = x }
    pmed[k] = m % 2 ? v[(m + 1) / 2] : (v[m / 2] + v[m / 2 + 1]) / 2
    plo[k] = v[1]; phi[k] = v[m]; pn[k] = m; pok[k] = 0
    for (a = 1; a <= m; a++) pok[k] += at_least ? v[a] >= bound : v[a] <= bound
  }
  /^pair / { pair_stats($2 " " $3 " " $4, 5, 1.8, 1); next }
  /^costpair / { pair_stats("cost " $2, 3, 1.3, 0); next }
  /^film / { nfilm++; fm[nfilm] = $2; fw[nfilm] = $3; fd[nfilm] = $4; fc[nfilm] = $5
             fb[nfilm] = $6; next }
  /^instr floor / { floor_ins = $3; next }
  /^instr / { ins[$2 " " $3 " " $4] = $5 }
  /^floor / { floor_nb = $2; floor_one = $3; floor_ns = $3; floor_gather = $5 + 0
              for (k = 4; k <= 5; k++) if ($k > 0 && $k < floor_ns) floor_ns = $k }
  function r(a, b) { return (b > 0) ? a / b : 0 }
  END {
    printf "\n%-5s %-9s %-4s %7s %12s %14s %14s %9s %9s\n", "proto", "code", "kind", "threads",
           "psteps/s", "psteps/CPU-s", "bytes/particle", "contacts", "bridges"
    for (p = 1; p <= 3; p++) for (c = 1; c <= 2; c++) for (v = 1; v <= 2; v++)
      for (t = 1; t <= 2; t++) {
        proto = p == 1 ? "full" : (p == 2 ? "same" : "frozen"); code = c == 1 ? "wetdem" : "liggghts"
        kind = v == 1 ? "dry" : "wet"; key = proto " " code " " kind " " t
        if (!(key in rate)) continue
        b = code == "wetdem" ? wb : lb
        printf "%-5s %-9s %-4s %7d %12.4g %14s %14.0f %9s %9s\n", proto, code, kind, t,
               rate[key], (cpu[key] > 0 ? sprintf("%.4g", cpu[key]) : "-"),
               (kb[key] - b) * 1024 / n, con[key], bri[key]
      }
    for (p = 1; p <= 3; p++) {
      proto = p == 1 ? "full" : (p == 2 ? "same" : "frozen")
      if (p == 1) printf "\nfull protocol (%d timed steps after the settling steps):\n", steps
      if (p == 2) printf "same-state protocol (%d timed steps from one shared state):\n", same
      if (p == 3) printf "frozen-configuration protocol (%d steps of %s s from that state):\n",
                         fsteps, fdt
      for (v = 1; v <= 2; v++) {
        kind = v == 1 ? "dry" : "wet"; w = proto " wetdem " kind; l = proto " liggghts " kind
        if (rate[l " 1"] > 0)
          printf "  %s: wetdem / LIGGGHTS per core  %.2fx wall, %.2fx CPU (target >= 2)\n", kind,
                 r(rate[w " 1"], rate[l " 1"]), r(cpu[w " 1"], cpu[l " 1"])
        printf "  %s: wetdem 2-thread speed-up       %.2fx (target >= 1.8)", kind,
               r(rate[w " 2"], rate[w " 1"])
        if (rate[l " 2"] > 0) printf "; LIGGGHTS 2 ranks %.2fx", r(rate[l " 2"], rate[l " 1"])
        printf " (best of each)\n"
        for (c = 1; c <= 2; c++) {
          pk = proto " " (c == 1 ? "wetdem" : "liggghts") " " kind
          if (pk in pmed)
            printf "  %s: %s speed-up, %d pairs back to back: median %.2fx" \
                   " (%.2f-%.2f; %d of %d at >= 1.8)\n", kind,
                   c == 1 ? "wetdem 2-thread" : "LIGGGHTS 2-rank", pn[pk], pmed[pk], plo[pk],
                   phi[pk], pok[pk], pn[pk]
        }
      }
      w = proto " wetdem "; l = proto " liggghts "
      printf "  cost wet / dry (1 thread): wetdem %.2fx wall, %.2fx CPU", r(rate[w "dry 1"],
             rate[w "wet 1"]), r(cpu[w "dry 1"], cpu[w "wet 1"])
      if (rate[l "wet 1"] > 0)
        printf "; LIGGGHTS %.2fx wall, %.2fx CPU", r(rate[l "dry 1"], rate[l "wet 1"]),
               r(cpu[l "dry 1"], cpu[l "wet 1"])
      note = p == 1 ? " (different final states)" : " (best of each, between LIGGGHTS runs)"
      if (p == 2) note = " (the wet run ends with more contacts)"
      printf "%s\n", note
      ck = "cost " proto
      if (ck in pmed)
        printf "  cost wet / dry (1 thread), %d pairs of a dry and a wet run back to back: median" \
               " %.2fx (%.2f-%.2f; %d of %d at <= 1.3; target <= 1.3)\n", pn[ck], pmed[ck],
               plo[ck], phi[ck], pok[ck], pn[ck]
      if (p == 3 && floor_nb > 0 && rate[w "dry 1"] > 0)
        printf "  the floor (bench/bridge_floor.c: the bare loop over the %d bridges apart of this" \
               " state, no engine): %.1f ns per bridge-step (one pair at a time %.1f; %s); on" \
               " top of the dry run it alone gives a wet / dry cost of %.2fx\n", floor_nb,
               floor_ns, floor_one, (floor_gather > 0) ? sprintf("eight at a time by AVX-512" \
               " gathers from arrays by component %.1f", floor_gather) : "no AVX-512 gathers" \
               " on this processor", 1 + floor_nb * floor_ns * 1e-9 * rate[w "dry 1"] / n
      if (p == 3 && nfilm > 0) { # (liquid: 3 delta / R of the mean radius, 0.95 mm)
        printf "  cost wet / dry against the film thickness (dry and wet back to back, best of" \
               " each; target <= 1.3):"
        for (f = 1; f <= nfilm; f++)
          printf "%s %g um films (%.1f %% liquid) %.2fx, %d pairs within the films (%d contacts)",
                 f == 1 ? "" : ";", fm[f] * 1e6, 300 * fm[f] / 0.95e-3, r(fd[f], fw[f]), fb[f],
                 fc[f]
        printf "\n"
      }
      nsteps = p == 1 ? steps : (p == 2 ? same : fsteps) # ns per particle-step of a phase:
      printf "  wetdem phases [ns per particle-step], 1 thread / 2 threads (speed-up):"
      for (v = 1; v <= 2; v++) {
        kind = v == 1 ? "dry" : "wet"; a = w kind " 1"; b = w kind " 2"
        printf "%s %s kick-drift %.1f / %.1f (%.2fx), forces %.1f / %.1f (%.2fx)",
               v == 1 ? "" : ";", kind, 1e9 * kick[a] / (n * nsteps), 1e9 * kick[b] / (n * nsteps),
               r(kick[a], kick[b]), 1e9 * frc[a] / (n * nsteps), 1e9 * frc[b] / (n * nsteps),
               r(frc[a], frc[b])
      }
      printf "\n"
    }
    if (length(ins) > 0)
      printf "instructions per particle-step (callgrind, 1 thread, %d steps minus 0):\n", isteps
    for (p = 2; p <= 3; p++) {
      proto = p == 2 ? "same" : "frozen"; w = proto " wetdem "; l = proto " liggghts "
      if (!((w "dry") in ins)) continue
      printf "  %-6s wetdem dry %d, wet %d (wet / dry %.2fx)", proto, ins[w "dry"], ins[w "wet"],
             r(ins[w "wet"], ins[w "dry"])
      if ((l "dry") in ins)
        printf "; LIGGGHTS dry %d, wet %d (%.2fx); LIGGGHTS / wetdem dry %.2fx, wet %.2fx",
               ins[l "dry"], ins[l "wet"], r(ins[l "wet"], ins[l "dry"]),
               r(ins[l "dry"], ins[w "dry"]), r(ins[l "wet"], ins[w "wet"])
      if (p == 3 && floor_ins > 0 && floor_nb > 0)
        printf "; the floor %d per bridge apart, on top of the dry step %.2fx", floor_ins,
               1 + floor_nb * floor_ins / (n * ins[w "dry"])
      printf "\n"
    }
  }' "$res" | tee "$out/summary.txt"

# ---- figure ----
# The three targets in one figure (bench/many_figure.py; matplotlib from Debian, which make
# bench installs): $out/many_bench.png. docs/figures/many_bench.png is a copy of a run's.
if /usr/bin/python3 -c "import matplotlib" 2>/dev/null; then
  /usr/bin/python3 bench/many_figure.py --results "$res" --out "$out/many_bench.png" --n "$N"
else
  echo "20-many: python3-matplotlib not installed: figure skipped (scripts/install-deps bench)" >&2
fi
