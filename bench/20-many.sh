#!/usr/bin/env bash
# 20-many.sh — many-particle benchmark, wetdem against LIGGGHTS 3.8 on the same system in one
# run: N polydisperse spheres settling in a closed box (bench/many_bench.c describes it), dry
# (Hertz-Mindlin; LIGGGHTS model hertz tangential history) and wet (wetdem sb + capillary;
# LIGGGHTS cohesion easo/capillary/viscous), on 1 and 2 threads (LIGGGHTS: MPI ranks).
# Reports particle-steps per second (wall clock of the timed steps, after untimed settling),
# memory per particle ((max RSS - RSS of a 1-particle run) / N) and the ratios against the
# targets: >= 2x LIGGGHTS per core dry and wet, >= 1.8x speed-up on 2 threads, wet <= 1.3x dry.
#
# Usage: bench/20-many.sh [WETDEM_CLI]    (make bench passes the CLI; it is not needed here)
# Environment: N (20000), SETTLE (500), STEPS (1500) — about 3 minutes on 2 cores;
# OMP_WAIT_POLICY (default passive: spinning threads collapse when the cores are shared).
# Per-core figures are also given per CPU-second (user + system time of the timed steps; for
# LIGGGHTS the CPU time of a settle-only run is subtracted), which a loaded machine distorts
# far less than the wall clock.
# Results go to build/bench/many/ (logs, results.txt). The ratios are printed, not enforced:
# the machine may be shared, which the load average printed with the results shows.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
cd "$root"
N=${N:-20000}
SETTLE=${SETTLE:-500}
STEPS=${STEPS:-1500}
out=build/bench/many
mkdir -p "$out"
res="$out/results.txt"
: > "$res"

cc -std=c11 -D_DEFAULT_SOURCE -O2 -fopenmp -Iinclude bench/many_bench.c build/libwetdem.a \
   -lsundials_cvode -lsundials_nvecserial -lgsl -lgslcblas -linih -lm -o "$out/many_bench"
"$out/many_bench" --n "$N" --data "$out/system.data"
"$out/many_bench" --n 1 --data "$out/one.data"

field() { sed -n "s/.*$1=\([^ ]*\).*/\1/p"; }
export OMP_WAIT_POLICY=${OMP_WAIT_POLICY:-passive}

# ---- wetdem ----
base_kb=$(OMP_NUM_THREADS=1 "$out/many_bench" --n 1 --settle 1 --steps 1 | field maxrss_kb)
for variant in dry wet; do
  for t in 1 2; do
    flag=""; [ "$variant" = wet ] && flag="--wet"
    line=$(OMP_NUM_THREADS=$t OMP_PROC_BIND=false "$out/many_bench" $flag --n "$N" \
           --settle "$SETTLE" --steps "$STEPS")
    echo "$line" | tee -a "$out/wetdem.log"
    rate=$(echo "$line" | field psteps_per_s)
    kb=$(echo "$line" | field maxrss_kb)
    cpu=$(echo "$line" | field cpu_seconds)
    echo "wetdem $variant $t $rate $kb $(awk -v n="$N" -v s="$STEPS" -v c="$cpu" \
         'BEGIN{printf "%.4g", n*s/c}')" >> "$res"
  done
done

# ---- LIGGGHTS ----
if command -v liggghts >/dev/null && command -v mpirun >/dev/null; then
  deck=$root/bench/liggghts
  run_lg() { # variant ranks data n [steps] -> "rate kb cpu_seconds"
    local log="$out/liggghts_$1_$2.log" steps=${5:-$STEPS}
    /usr/bin/time -f "maxrss_kb=%M cpu=%U+%S" -o "$out/time_$1_$2.txt" \
      mpirun --allow-run-as-root --oversubscribe -np "$2" liggghts -in "$deck/$1.in" \
      -var deckdir "$deck" -var data "$3" -var nsettle "$SETTLE" -var nsteps "$steps" \
      -log "$log" -screen none -nocite
    # the second "Loop time" line is the timed run
    local secs
    secs=$(grep "^Loop time" "$log" | sed -n 2p | awk '{print $4}')
    local kb cpu
    kb=$(field maxrss_kb < "$out/time_$1_$2.txt")
    cpu=$(field cpu < "$out/time_$1_$2.txt" | bc -l)
    echo "$(awk -v n="$4" -v s="$STEPS" -v t="$secs" 'BEGIN{printf "%.4g", n*s/t}') $kb $cpu"
  }
  lg_base=$(run_lg dry 1 "$out/one.data" 1 | awk '{print $2}')
  for variant in dry wet; do
    for t in 1 2; do
      r=$(run_lg "$variant" "$t" "$out/system.data" "$N")
      if [ "$t" = 1 ]; then # CPU time of the timed steps: minus a settle-only run
        c0=$(run_lg "$variant" 1 "$out/system.data" "$N" 0 | awk '{print $3}')
        r=$(echo "$r" | awk -v c0="$c0" -v n="$N" -v s="$STEPS" \
            '{printf "%s %s %.4g", $1, $2, n*s/($3-c0)}')
      else
        r=$(echo "$r" | awk '{print $1, $2, 0}')
      fi
      echo "liggghts $variant $t $r" | tee -a "$out/liggghts.log"
      echo "liggghts $variant $t $r" >> "$res"
    done
  done
else
  echo "20-many: liggghts or mpirun not installed: LIGGGHTS half skipped (scripts/install-deps bench)"
  lg_base=0
fi

# ---- report ----
echo "load average during the run: $(cut -d' ' -f1-3 /proc/loadavg), $(nproc) cores" | tee -a "$res"
awk -v n="$N" -v wb="$base_kb" -v lb="$lg_base" '
  /^(wetdem|liggghts) / { k = $1 " " $2 " " $3; rate[k] = $4; kb[k] = $5; cpu[k] = $6 }
  END {
    printf "\n%-9s %-4s %8s %16s %18s %14s\n", "code", "kind", "threads", "psteps/s",
           "psteps/CPU-s", "bytes/particle"
    for (c = 1; c <= 2; c++) for (v = 1; v <= 2; v++) for (t = 1; t <= 2; t++) {
      code = c == 1 ? "wetdem" : "liggghts"; kind = v == 1 ? "dry" : "wet"
      key = code " " kind " " t
      if (!(key in rate)) continue
      b = code == "wetdem" ? wb : lb
      printf "%-9s %-4s %8d %16.4g %18.4g %14.0f\n", code, kind, t, rate[key], cpu[key],
             (kb[key] - b) * 1024 / n
    }
    printf "\n"
    for (v = 1; v <= 2; v++) {
      kind = v == 1 ? "dry" : "wet"
      w1 = rate["wetdem " kind " 1"]; w2 = rate["wetdem " kind " 2"]
      l1 = rate["liggghts " kind " 1"]
      if (l1 > 0) printf "%s: wetdem / LIGGGHTS per core  %.2fx wall, %.2fx CPU (target >= 2)\n",
                         kind, w1 / l1, cpu["wetdem " kind " 1"] / cpu["liggghts " kind " 1"]
      printf "%s: wetdem 2-thread speed-up       %.2fx (target >= 1.8)\n", kind, w2 / w1
    }
    printf "wetdem cost wet / dry (1 thread)    %.2fx (target <= 1.3)\n",
           rate["wetdem dry 1"] / rate["wetdem wet 1"]
    l1d = rate["liggghts dry 1"]; l1w = rate["liggghts wet 1"]
    if (l1w > 0) printf "LIGGGHTS cost wet / dry (1 rank)   %.2fx\n", l1d / l1w
  }' "$res" | tee "$out/summary.txt"
