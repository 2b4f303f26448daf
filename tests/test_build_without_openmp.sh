#!/usr/bin/env bash
# Every C file of the library and the tool compiles cleanly without OpenMP (its pragmas then
# ignored): clang -std=c11 -fsyntax-only -Wall -Wextra -Werror, as CI checks touched files, but
# without -fopenmp. A variable read only by an `if (...)` clause of an OpenMP pragma was then
# unused, an error under -Werror. (gcc warns about every ignored OpenMP pragma under -Wall, so
# the check is clang's; without clang it says so and passes.)
set -u
here=$(cd "$(dirname "$0")/.." && pwd)
if ! command -v clang >/dev/null 2>&1; then
  echo "clang not found: check skipped"
  exit 0
fi
failed=0
for f in "$here"/src/*.c "$here"/cli/*.c; do
  if ! out=$(clang -std=c11 -D_DEFAULT_SOURCE -fsyntax-only -Wall -Wextra -Werror \
    -I"$here/include" -I"$here/src" -I"$here/cli" "$f" 2>&1); then
    echo "FAIL ${f#"$here"/}: does not compile without OpenMP"
    printf '%s\n' "$out"
    failed=1
  fi
done
[ $failed -eq 0 ] && echo "every src/*.c and cli/*.c compiles without OpenMP"
exit $failed
