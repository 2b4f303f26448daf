# Sourced by the validation pieces of the many-particle mode and by scripts/paraview (not run
# on its own): `piece_start NAME OUT "$@"` checks that the piece was given the CLI's path,
# sets cli (that path), out (OUT, emptied and created) and S (the shipped scenarios), and
# exports OMP_WAIT_POLICY=passive unless set (on a shared machine, spinning OpenMP threads
# slow a run several fold: docs/many.md).
piece_start() {
  local name=$1
  out=$2
  cli=${3:-}
  if [ -z "$cli" ]; then
    echo "usage: $name PATH_TO_WETDEM_CLI   (from the repository root)" >&2
    exit 2
  fi
  S=examples/scenarios
  export OMP_WAIT_POLICY=${OMP_WAIT_POLICY:-passive}
  rm -rf "$out"
  mkdir -p "$out"
}
