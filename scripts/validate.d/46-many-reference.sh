#!/usr/bin/env bash
# The many-particle engine against an independent reference in Python (tools/many_reference.py,
# written from docs/many.md, docs/models.md and docs/derivations/, not from the C code): 41
# scenarios of 1 to 512 spheres (unequal radii and materials, walls, periodic faces, fixed
# spheres, gravity, hertz/hooke + mindlin, sb, db, davis, nase, capillary, reynolds, nijssen,
# the min-separation models fixed, roughness, ehd, max and glass; 512 spheres on 2, 3 and 4
# threads; ten with the step derived by the engine and by the reference (with fixed spheres,
# reynolds, nijssen with either damping, hertz's exact dashpot, ehd and glass among them);
# five stopped and resumed from their checkpoint) run through `wetdem run` with a binary
# frame every 25 steps, and the state compared at each frame, the energy budget per model and
# the speeds behind the step (speed scale, bound, largest half-step speed) at the end. Then
# 23 deliberate errors of the reference (a lever arm, a record, the Coulomb limit, the
# periodic image, the power, the derived step and its fall (the rule before, over the three
# axes together; the fixed spheres' term left out), reynolds as a jump, nijssen's dashpots
# left out, the other damping's coefficient, glass's h_min, roughness, the histories at a
# restart, the pairs across thread blocks, the largest speed over full steps or the resumed
# part, the speed bound) must be detected.
# Usage: scripts/validate.d/46-many-reference.sh PATH_TO_WETDEM_CLI   (from the repository root)
set -euo pipefail
. scripts/piece-start.sh
piece_start 46-many-reference.sh out/validate/many_reference "$@"

/usr/bin/python3 tools/many_reference.py --wetdem "$cli" --every 25 | tee "$out/cases.txt"
/usr/bin/python3 tools/many_reference.py --wetdem "$cli" --every 25 --mutants \
    | tee "$out/mutants.txt"
