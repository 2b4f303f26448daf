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
# Reports particle-steps per second (wall clock of the timed steps), per CPU-second for the
# full runs on 1 thread (user + system time of the timed steps; for LIGGGHTS the CPU time of a
# settle-only run is subtracted), memory per particle ((max RSS - RSS of a 1-particle run) / N)
# and the ratios against the targets: >= 2x LIGGGHTS per core dry and wet, >= 1.8x speed-up on
# 2 threads, wet <= 1.3x dry.
#
# Usage: bench/20-many.sh [WETDEM_CLI]    (make bench passes the CLI; it is not needed here)
# Environment: N (20000), SETTLE (500), STEPS (1500), STATE (3000), SAME_STEPS (300),
# FROZEN_STEPS (300), FROZEN_DT (1e-9) — about 5 minutes on 2 cores; OMP_WAIT_POLICY (default passive: spinning threads collapse when the
# cores are shared).
# Results go to build/bench/many/ (logs, results.txt, summary.txt). The ratios are printed, not
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
out=build/bench/many
mkdir -p "$out"
res="$out/results.txt"
: > "$res"
: > "$out/wetdem.log"
: > "$out/liggghts.log"

cc -std=c11 -D_DEFAULT_SOURCE -O2 -fopenmp -Iinclude bench/many_bench.c build/libwetdem.a \
   -lsundials_cvode -lsundials_nvecserial -lgsl -lgslcblas -linih -lm -o "$out/many_bench"
"$out/many_bench" --n "$N" --data "$out/system.data"
"$out/many_bench" --n 1 --data "$out/one.data"

field() { sed -n "s/.*$1=\([^ ]*\).*/\1/p"; }
export OMP_WAIT_POLICY=${OMP_WAIT_POLICY:-passive}
have_lg=false
command -v liggghts >/dev/null && command -v mpirun >/dev/null && have_lg=true
deck=$root/bench/liggghts

# wetdem run: protocol variant threads [many_bench args] -> results line
run_wd() {
  local proto=$1 variant=$2 t=$3 flag="" steps=$STEPS
  shift 3
  [ "$variant" = wet ] && flag="--wet"
  [ "$proto" = same ] && steps=$SAME_STEPS
  [ "$proto" = frozen ] && steps=$FROZEN_STEPS
  local line
  line=$(OMP_NUM_THREADS=$t OMP_PROC_BIND=false "$out/many_bench" $flag "$@")
  echo "$proto $line" | tee -a "$out/wetdem.log" >&2
  local rate kb cpu
  rate=$(echo "$line" | field psteps_per_s)
  kb=$(echo "$line" | field maxrss_kb)
  cpu=$(echo "$line" | field cpu_seconds)
  echo "$proto wetdem $variant $t $rate $kb $(awk -v n="$N" -v s="$steps" -v c="$cpu" \
       'BEGIN{printf "%.4g", n*s/c}') $(echo "$line" | field contacts) \
       $(echo "$line" | field bridges)" >> "$res"
}

# LIGGGHTS run: variant ranks data nsettle nsteps [dt] -> "rate kb cpu_seconds"
run_lg() {
  local log="$out/liggghts_$1_$2_$4.log"
  /usr/bin/time -f "maxrss_kb=%M cpu=%U+%S" -o "$out/time_$1_$2.txt" \
    mpirun --allow-run-as-root --oversubscribe -np "$2" liggghts -in "$deck/$1.in" \
    -var deckdir "$deck" -var data "$3" -var nsettle "$4" -var nsteps "$5" \
    -var dt "${6:-1e-5}" -log "$log" -screen none -nocite
  local secs kb cpu # the second "Loop time" line is the timed run
  secs=$(grep "^Loop time" "$log" | sed -n 2p | awk '{print $4}')
  kb=$(field maxrss_kb < "$out/time_$1_$2.txt")
  cpu=$(field cpu < "$out/time_$1_$2.txt" | bc -l)
  echo "$(awk -v n="$N" -v s="$5" -v t="$secs" 'BEGIN{printf "%.4g", n*s/t}') $kb $cpu"
}

lg_base=0
$have_lg && lg_base=$(run_lg dry 1 "$out/one.data" 0 1 | awk '{print $2}')
base_kb=$(OMP_NUM_THREADS=1 "$out/many_bench" --n 1 --settle 1 --steps 1 | field maxrss_kb)

# ---- full protocol ----
for variant in dry wet; do
  for t in 1 2; do
    run_wd full "$variant" "$t" --n "$N" --settle "$SETTLE" --steps "$STEPS"
    $have_lg || continue
    r=$(run_lg "$variant" "$t" "$out/system.data" "$SETTLE" "$STEPS")
    if [ "$t" = 1 ]; then # CPU time of the timed steps: minus a settle-only run
      c0=$(run_lg "$variant" 1 "$out/system.data" "$SETTLE" 0 | awk '{print $3}')
      r=$(echo "$r" | awk -v c0="$c0" -v n="$N" -v s="$STEPS" \
          '{printf "%s %s %.4g", $1, $2, n*s/($3-c0)}')
    else
      r=$(echo "$r" | awk '{print $1, $2, 0}')
    fi
    echo "full liggghts $variant $t $r" | tee -a "$out/liggghts.log" >&2
    echo "full liggghts $variant $t $r - -" >> "$res"
  done
done

# ---- same-state protocol ----
OMP_NUM_THREADS=2 "$out/many_bench" --n "$N" --settle "$STATE" --steps 0 \
  --state-out "$out/state.data" > /dev/null
for variant in dry wet; do
  for t in 1 2; do
    run_wd same "$variant" "$t" --state-in "$out/state.data" --settle 0 --steps "$SAME_STEPS"
    $have_lg || continue
    r=$(run_lg "$variant" "$t" "$out/state.data" 0 "$SAME_STEPS" | awk '{print $1, $2, 0}')
    echo "same liggghts $variant $t $r" | tee -a "$out/liggghts.log" >&2
    echo "same liggghts $variant $t $r - -" >> "$res"
  done
done

# ---- frozen-configuration protocol ----
for variant in dry wet; do
  for t in 1 2; do
    run_wd frozen "$variant" "$t" --state-in "$out/state.data" --settle 0 \
      --steps "$FROZEN_STEPS" --dt "$FROZEN_DT"
    $have_lg || continue
    r=$(run_lg "$variant" "$t" "$out/state.data" 0 "$FROZEN_STEPS" "$FROZEN_DT" |
        awk '{print $1, $2, 0}')
    echo "frozen liggghts $variant $t $r" | tee -a "$out/liggghts.log" >&2
    echo "frozen liggghts $variant $t $r - -" >> "$res"
  done
done
$have_lg || echo "20-many: liggghts or mpirun not installed: LIGGGHTS half skipped" \
  "(scripts/install-deps bench)"

# ---- report ----
echo "load average after the run: $(cut -d' ' -f1-3 /proc/loadavg), $(nproc) cores" | tee -a "$res"
awk -v n="$N" -v wb="$base_kb" -v lb="$lg_base" -v steps="$STEPS" -v same="$SAME_STEPS" \
    -v fsteps="$FROZEN_STEPS" -v fdt="$FROZEN_DT" '
  /^(full|same|frozen) / { k = $1 " " $2 " " $3 " " $4; rate[k] = $5; kb[k] = $6; cpu[k] = $7
                    con[k] = $8; bri[k] = $9 }
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
    printf "\nfull protocol (%d timed steps after the settling steps):\n", steps
    for (v = 1; v <= 2; v++) {
      kind = v == 1 ? "dry" : "wet"; w = "full wetdem " kind; l = "full liggghts " kind
      if (rate[l " 1"] > 0)
        printf "  %s: wetdem / LIGGGHTS per core  %.2fx wall, %.2fx CPU (target >= 2)\n", kind,
               r(rate[w " 1"], rate[l " 1"]), r(cpu[w " 1"], cpu[l " 1"])
      printf "  %s: wetdem 2-thread speed-up       %.2fx (target >= 1.8)", kind,
             r(rate[w " 2"], rate[w " 1"])
      if (rate[l " 2"] > 0) printf "; LIGGGHTS 2 ranks %.2fx", r(rate[l " 2"], rate[l " 1"])
      printf "\n"
    }
    printf "  cost wet / dry (1 thread): wetdem %.2fx", r(rate["full wetdem dry 1"],
           rate["full wetdem wet 1"])
    if (rate["full liggghts wet 1"] > 0)
      printf ", LIGGGHTS %.2fx", r(rate["full liggghts dry 1"], rate["full liggghts wet 1"])
    printf " (different final states)\n"
    printf "same-state protocol (%d timed steps from one shared state):\n", same
    for (v = 1; v <= 2; v++) {
      kind = v == 1 ? "dry" : "wet"; w = "same wetdem " kind; l = "same liggghts " kind
      if (rate[l " 1"] > 0)
        printf "  %s: wetdem / LIGGGHTS per core  %.2fx wall (target >= 2)\n", kind,
               r(rate[w " 1"], rate[l " 1"])
      printf "  %s: wetdem 2-thread speed-up       %.2fx (target >= 1.8)\n", kind,
             r(rate[w " 2"], rate[w " 1"])
    }
    printf "  cost wet / dry (1 thread): wetdem %.2fx", r(rate["same wetdem dry 1"],
           rate["same wetdem wet 1"])
    if (rate["same liggghts wet 1"] > 0)
      printf ", LIGGGHTS %.2fx", r(rate["same liggghts dry 1"], rate["same liggghts wet 1"])
    printf " (the wet run ends with more contacts)\n"
    printf "frozen-configuration protocol (%d steps of %s s from the same state):\n", fsteps, fdt
    for (v = 1; v <= 2; v++) {
      kind = v == 1 ? "dry" : "wet"; w = "frozen wetdem " kind; l = "frozen liggghts " kind
      if (rate[l " 1"] > 0)
        printf "  %s: wetdem / LIGGGHTS per core  %.2fx wall (target >= 2)\n", kind,
               r(rate[w " 1"], rate[l " 1"])
      printf "  %s: wetdem 2-thread speed-up       %.2fx (target >= 1.8)\n", kind,
             r(rate[w " 2"], rate[w " 1"])
    }
    printf "  cost wet / dry (1 thread): wetdem %.2fx (target <= 1.3)",
           r(rate["frozen wetdem dry 1"], rate["frozen wetdem wet 1"])
    if (rate["frozen liggghts wet 1"] > 0)
      printf ", LIGGGHTS %.2fx", r(rate["frozen liggghts dry 1"], rate["frozen liggghts wet 1"])
    printf "\n"
  }' "$res" | tee "$out/summary.txt"
