#!/usr/bin/env bash
# The many-particle VTK output read by VTK's own legacy reader (Debian python3-vtk9, the
# reader ParaView uses for .vtk files) and checked by tools/check_vtk_with_vtk.py: the
# .vtk.series indexes as ParaView reads them, frames and links files without a reader error,
# the arrays of docs/many.md, lines as long as the gap they carry, the same numbers as
# tools/wetdem_vtk.py, and a binary and an ASCII run of one scenario bit for bit the same.
# Runs: 30 ms of the settling example (links; periodic in x and y, so links cross the box's
# faces) in binary and in ASCII, and 20 ms of the agglomeration example (periodic in x, y and
# z) with links; then the outputs of 40-many.sh when present.
# Usage: scripts/validate.d/42-vtk.sh PATH_TO_WETDEM_CLI   (from the repository root)
set -euo pipefail
. scripts/piece-start.sh
piece_start 42-vtk.sh out/validate/vtk "$@"

settle=(--set run.t_end=0.03 --set dump.vtk_every=500)
echo "-- settling, 30 ms, binary frames and links"
"$cli" run $S/many_settling.ini "${settle[@]}" --out "$out/settling_binary" > /dev/null
echo "-- the same in ASCII"
"$cli" run $S/many_settling.ini "${settle[@]}" --set dump.vtk_binary=no \
    --out "$out/settling_ascii" > /dev/null
echo "-- agglomeration, 20 ms, with links"
"$cli" run $S/many_agglomeration.ini --set run.t_end=0.02 --set dump.vtk_every=1000 \
    --set dump.vtk_links=yes \
    --out "$out/agglomeration" > /dev/null

runs=("$out/agglomeration")
for d in out/validate/many/cradle out/validate/many/settling out/validate/many/agglomeration; do
  [ -d "$d" ] && runs+=("$d")
done
/usr/bin/python3 tools/check_vtk_with_vtk.py --all-kinds "${runs[@]}" \
    --same "$out/settling_binary" "$out/settling_ascii"

echo "-- tools/wetdem_vtk.py refuses a frame cut short (a crash mid-write), naming the file"
/usr/bin/python3 - "$out" <<'PY'
import os, random, sys
sys.path.insert(0, "tools")
from wetdem_vtk import read_vtk
out = sys.argv[1]
files = [f"{out}/settling_binary/particles_000001.vtk", f"{out}/settling_ascii/particles_000001.vtk",
         f"{out}/agglomeration/particles_links_000001.vtk"]
cut, rng, bad = f"{out}/cut.vtk", random.Random(7), []
for f in files:
    data, whole = open(f, "rb").read(), None
    whole = read_vtk(f)
    for n in sorted({0, 10, len(data) - 2} | {rng.randrange(len(data)) for _ in range(100)}):
        open(cut, "wb").write(data[:n])
        try:
            got = read_vtk(cut)
            if set(got) != set(whole) or any(got[k].shape != whole[k].shape for k in got):
                bad.append(f"{f} cut at {n}: read with arrays missing or short")
        except ValueError as e:
            if cut not in str(e):
                bad.append(f"{f} cut at {n}: the message does not name the file: {e}")
os.remove(cut)
for b in bad:
    print("  [FAIL]", b)
print(f"  [{'FAIL' if bad else 'ok'}] {3 * 100} cuts of 3 files: every one refused, naming the file")
sys.exit(1 if bad else 0)
PY
