#!/usr/bin/env bash
# Tests of `make install` and `make uninstall`: a staged install (DESTDIR) puts every file under
# the stage with PREFIX written into wetdem.pc; the shared library's SONAME is the name of the
# installed link to it; a program built against an install through pkg-config, linked to the
# shared and to the static library, prints the same as the example built in the tree; the
# installed CLI reports the version pkg-config does; the README's C example builds the same way
# and prints what the README says; `make uninstall` leaves no file of its
# own behind, and removes none it did not install.
# Run by `make test`: the nested make inherits the outer one's variables (BUILD, CC,
# EXTRA_CFLAGS), so a sanitizer build installs its own objects; WETDEM_EXTRA_CFLAGS carries the
# sanitizer flags to the compiles here.
set -u
here=$(cd "$(dirname "$0")/.." && pwd)
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cc=${CC:-gcc}
extra=${WETDEM_EXTRA_CFLAGS:-}
fails=0
fail() { echo "FAIL: $*"; fails=$((fails + 1)); }

version=$(sed -n 's/^#define WETDEM_VERSION "\(.*\)"/\1/p' "$here/include/wetdem.h")

# 1. Staged: files under DESTDIR, the .pc naming the final prefix.
make -s -C "$here" install DESTDIR="$work/stage" PREFIX=/usr/local >"$work/log" 2>&1 \
  || { cat "$work/log"; fail "make install DESTDIR=... failed"; }
p="$work/stage/usr/local"
for f in bin/wetdem include/wetdem.h lib/libwetdem.a "lib/libwetdem.so.$version" \
         lib/pkgconfig/wetdem.pc share/wetdem/examples/01_pair_force/main.c \
         share/wetdem/examples/scenarios/nijssen_head_on.ini share/wetdem/wetdem_vtk.py \
         share/doc/wetdem/README.md share/doc/wetdem/docs/models.md; do
  [ -f "$p/$f" ] || fail "staged install lacks $f"
done
grep -qx 'prefix=/usr/local' "$p/lib/pkgconfig/wetdem.pc" || fail "wetdem.pc does not name PREFIX"
soname=$(objdump -p "$p/lib/libwetdem.so.$version" | awk '$1 == "SONAME" {print $2}')
[ -n "$soname" ] && [ -L "$p/lib/$soname" ] || fail "no link named for the SONAME ($soname)"
[ "$(readlink -f "$p/lib/libwetdem.so")" = "$(readlink -f "$p/lib/libwetdem.so.$version")" ] \
  || fail "libwetdem.so does not lead to libwetdem.so.$version"

# 2. Installed to a prefix, used through pkg-config.
make -s -C "$here" install PREFIX="$work/p" >"$work/log" 2>&1 \
  || { cat "$work/log"; fail "make install PREFIX=... failed"; }
export PKG_CONFIG_PATH="$work/p/lib/pkgconfig"
[ "$(pkg-config --modversion wetdem)" = "$version" ] || fail "pkg-config --modversion"
src="$here/examples/01_pair_force/main.c"
# shellcheck disable=SC2046,SC2086
$cc -std=c11 $extra $(pkg-config --cflags wetdem) -o "$work/shared" "$src" \
  $(pkg-config --libs wetdem) -Wl,-rpath,"$work/p/lib" || fail "build against the shared library"
# shellcheck disable=SC2046,SC2086
$cc -std=c11 $extra $(pkg-config --cflags wetdem) -o "$work/static" "$src" -Wl,-Bstatic -lwetdem \
  -Wl,-Bdynamic $(pkg-config --static --libs wetdem | sed 's/ -lwetdem / /') \
  || fail "build against the static library"
ldd "$work/shared" | grep -q "$work/p/lib/libwetdem.so" || fail "shared build not linked to the install"
ldd "$work/static" | grep -q libwetdem && fail "static build linked to a shared libwetdem"
"$work/shared" >"$work/out_shared" || fail "program on the shared library exited $?"
"$work/static" >"$work/out_static" || fail "program on the static library exited $?"
[ -s "$work/out_shared" ] && cmp -s "$work/out_shared" "$work/out_static" \
  || fail "shared and static builds print different output"
# The same as the tree's own build of the example (when it is there).
ex="$here/${WETDEM_BUILD:-build}/examples/01_pair_force"
[ -x "$ex" ] && { "$ex" | cmp -s - "$work/out_shared" || fail "output differs from $ex"; }
"$work/p/bin/wetdem" --version | grep -q "$version" || fail "installed wetdem --version"
# The README's C example, built as the README says (pkg-config, shared library), prints what the
# README says it prints.
awk '/^## A tiny C example/ {f = 1} f && /^```c/ {g = 1; next} g && /^```/ {exit} g' \
  "$here/README.md" >"$work/pair.c"
# shellcheck disable=SC2016
said=$(sed -n 's/^It prints `\([^`]*\)`.*/\1/p' "$here/README.md")
# shellcheck disable=SC2046,SC2086
$cc -std=c11 $extra "$work/pair.c" $(pkg-config --cflags --libs wetdem) -Wl,-rpath,"$work/p/lib" \
  -o "$work/pair" || fail "the README's C example does not build"
[ -n "$said" ] && [ "$("$work/pair")" = "$said" ] \
  || fail "the README's C example prints '$("$work/pair" 2>&1)', the README says '$said'"

# 3. Uninstall leaves nothing of its own, and what others put beside it.
echo mine >"$work/p/share/wetdem/mine.txt"
make -s -C "$here" uninstall PREFIX="$work/p" >"$work/log" 2>&1 || { cat "$work/log"; fail "make uninstall"; }
left=$(find "$work/p" \( -type f -o -type l \) | head -5)
[ "$left" = "$work/p/share/wetdem/mine.txt" ] || fail "make uninstall left or removed: '$left'"

[ $fails -eq 0 ] && echo "test_install: ok" || { echo "test_install: $fails failure(s)"; exit 1; }
