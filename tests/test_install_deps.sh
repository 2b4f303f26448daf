#!/usr/bin/env bash
# Tests of scripts/install-deps against stand-ins for dpkg-query, apt-get and sudo on PATH, so
# that nothing is installed: only the missing packages are asked for; a held apt lock is waited
# for and then the install goes on; any other `apt-get update` error, or a lock held past the
# wait, stops the script with a non-zero status before anything is installed; python3-vtk9 is
# not asked for beside python3-paraview, with which it conflicts (either serves the VTK check).
set -u
here=$(cd "$(dirname "$0")/.." && pwd)
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
mkdir -p "$work/bin"

# dpkg-query: every package is installed but those of FAKE_MISSING (libcmocka-dev by default).
cat >"$work/bin/dpkg-query" <<'EOF'
#!/usr/bin/env bash
for a in "$@"; do p=$a; done
for m in ${FAKE_MISSING:-libcmocka-dev}; do [ "$p" = "$m" ] && exit 1; done
printf 'install ok installed'
EOF
# apt-get: logs each call; `update` reports a held lock FAKE_LOCKED times, then succeeds, or
# fails with another error when FAKE_UPDATE_ERROR is set.
cat >"$work/bin/apt-get" <<'EOF'
#!/usr/bin/env bash
echo "apt-get $*" >>"$FAKE_LOG"
if [ "$1" = update ]; then
  n=$(grep -c '^apt-get update' "$FAKE_LOG")
  if [ -n "${FAKE_UPDATE_ERROR:-}" ]; then echo "E: $FAKE_UPDATE_ERROR" >&2; exit 100; fi
  if [ "$n" -le "${FAKE_LOCKED:-0}" ]; then
    echo "E: Could not get lock /var/lib/apt/lists/lock. It is held by process 1 (apt-get)" >&2
    exit 100
  fi
fi
exit 0
EOF
printf '#!/usr/bin/env bash\nexec "$@"\n' >"$work/bin/sudo"
chmod +x "$work/bin/"*

fails=0
run() { # run NAME ENV... : runs install-deps $SET (build) with the stand-ins; status in $rc,
  #       stderr in $err
  local name=$1
  shift
  : >"$work/log"
  err=$(env PATH="$work/bin:$PATH" FAKE_LOG="$work/log" INSTALL_DEPS_LOCK_POLL=0.01 "$@" \
    "$here/scripts/install-deps" "${SET:-build}" 2>&1 >/dev/null)
  rc=$?
  echo "# $name: exit $rc"
}
check() { # check DESCRIPTION COMMAND... : counts a failure when COMMAND fails
  local what=$1
  shift
  if ! "$@"; then
    echo "FAIL: $what"
    echo "  stderr: $err"
    echo "  calls: $(tr '\n' ';' <"$work/log")"
    fails=$((fails + 1))
  fi
}

run "lock held for three tries" FAKE_LOCKED=3
check "exits 0 once the lock is free" [ "$rc" -eq 0 ]
check "retries update until the lock is free (4 calls)" \
  [ "$(grep -c '^apt-get update' "$work/log")" -eq 4 ]
check "says it waits" grep -q "waiting for another package manager" <<<"$err"
check "installs only the missing package, waiting for dpkg's lock" \
  grep -qx 'apt-get install -y -qq --no-install-recommends -o DPkg::Lock::Timeout=600 libcmocka-dev' \
  "$work/log"

run "another update error" FAKE_UPDATE_ERROR="Failed to fetch"
check "exits non-zero" [ "$rc" -ne 0 ]
check "does not retry it" [ "$(grep -c '^apt-get update' "$work/log")" -eq 1 ]
check "installs nothing" bash -c "! grep -q '^apt-get install' '$work/log'"
check "passes the error on" grep -q "Failed to fetch" <<<"$err"

run "lock held past the wait" FAKE_LOCKED=1000 INSTALL_DEPS_LOCK_WAIT=0
check "exits non-zero" [ "$rc" -ne 0 ]
check "installs nothing" bash -c "! grep -q '^apt-get install' '$work/log'"
check "gives up at the deadline (1 call)" [ "$(grep -c '^apt-get update' "$work/log")" -eq 1 ]
check "names the held lock" grep -q "Could not get lock" <<<"$err"

installs() { grep '^apt-get install' "$work/log" | grep -qw -- "$1"; }
run "the locale sources missing" FAKE_MISSING=locales
check "the build set installs locales (test_locale's localedef)" installs locales
SET=validate run "VTK's Python module, neither package there" FAKE_MISSING="python3-vtk9 python3-paraview"
check "installs python3-vtk9" installs python3-vtk9
check "not python3-paraview" bash -c "! grep '^apt-get install' '$work/log' | grep -qw python3-paraview"
SET=validate run "VTK's Python module, ParaView's there" FAKE_MISSING="python3-vtk9"
check "installs nothing" bash -c "! grep -q '^apt-get install' '$work/log'"
SET=all run "every set, neither there" FAKE_MISSING="python3-vtk9 python3-paraview"
check "installs python3-paraview" installs python3-paraview
check "not the conflicting python3-vtk9" \
  bash -c "! grep '^apt-get install' '$work/log' | grep -qw python3-vtk9"

[ "$fails" -eq 0 ] && echo "install-deps: all checks passed"
[ "$fails" -eq 0 ]
