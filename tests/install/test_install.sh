#!/usr/bin/env bash
# test_install BUILD SOURCE CC: `cmake --install BUILD --prefix TMP`, then examples/embed built against TMP
# only (CMake: CMAKE_PREFIX_PATH=TMP; pkg-config: PKG_CONFIG_PATH=TMP/...), linked shared and static, run on
# a cube dropped onto a floor and on cases/user/floor_slide.scene; the installed polydyn CLI runs the slide.
set -uo pipefail
build=$1 src=$2 cc=$3
. "$src/tests/lib.sh"
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
prefix=$tmp/prefix

check "cmake --install into a fresh prefix" 'cmake --install "$build" --prefix "$prefix" >"$tmp/install.log" 2>&1'
pc=$(find "$prefix" -name polydyn.pc)
check "one polydyn.pc installed" '[ -n "$pc" ] && [ "$(echo "$pc" | wc -l)" -eq 1 ]'
libdir=$(dirname "$(dirname "$pc")")
check "libpolydyn.so (with its SONAME) and libpolydyn.a installed" \
  '[ -f "$libdir/libpolydyn.a" ] && [ -L "$libdir/libpolydyn.so" ] && readelf -d "$libdir/libpolydyn.so" | grep -q "SONAME.*libpolydyn.so.[0-9]"'
check "polydyn installed in bin/" '[ -x "$prefix/bin/polydyn" ]'

# Every installed header compiles alone (self-contained: it includes what it uses, nothing internal); the
# typedef keeps api.h's translation unit from being empty, which -Wpedantic refuses.
for h in "$prefix"/include/polydyn/*.h; do
  header=polydyn/$(basename "$h")
  check "$header compiles alone" \
    'printf "#include <%s>\ntypedef int notEmpty;\n" "$header" | "$cc" -std=c11 -Wall -Wextra -Wpedantic -Werror -fsyntax-only -I"$prefix/include" -x c -'
done

# The shared library exports exactly the PD_API declarations of the installed headers (polydyn/api.h).
grep -ho '^PD_API [^(\[]*' "$prefix"/include/polydyn/*.h | grep -o '[A-Za-z_0-9]*$' | sort >"$tmp/declared"
nm -D --defined-only "$libdir/libpolydyn.so" | awk '{print $3}' | sort >"$tmp/exported"
check "libpolydyn.so exports the $(wc -l <"$tmp/declared") declared names, nothing else" \
  'diff "$tmp/declared" "$tmp/exported" && [ -s "$tmp/declared" ]'

# The example, built with the installed CMake package: nothing of the build tree is visible to it.
check "examples/embed configures with find_package(polydyn)" \
  'cmake -S "$src/examples/embed" -B "$tmp/cmake" -DCMAKE_PREFIX_PATH="$prefix" -DCMAKE_C_COMPILER="$cc" \
     -DCMAKE_FIND_USE_PACKAGE_REGISTRY=OFF >"$tmp/cmake.log" 2>&1'
check "examples/embed builds (CMake, shared and static)" 'cmake --build "$tmp/cmake" >>"$tmp/cmake.log" 2>&1'
# loads_installed EXE: the libpolydyn.so that EXE loads is the installed one
loads_installed() {
  local loaded
  loaded=$(ldd "$1" | awk '$1 ~ /^libpolydyn\.so/ {print $3}')
  [ -n "$loaded" ] && [ "$(realpath "$loaded")" = "$(realpath "$libdir/libpolydyn.so")" ]
}
check "embed loads the installed libpolydyn.so" 'loads_installed "$tmp/cmake/embed"'
check "embed_static needs no libpolydyn.so" '! ldd "$tmp/cmake/embed_static" | grep -q libpolydyn'
# ... and with pkg-config
mkdir -p "$tmp/pc"
check "examples/embed builds (pkg-config, shared and static)" \
  'PKG_CONFIG_PATH="$(dirname "$pc")" make -s -C "$src/examples/embed" O="$tmp/pc" CC="$cc" >"$tmp/make.log" 2>&1'
check "pkg-config's embed loads the installed libpolydyn.so" 'loads_installed "$tmp/pc/embed"'
if [ $failed -ne 0 ]; then
  cat "$tmp"/*.log
  echo "$passed passed, $failed failed"
  exit 1
fi

# The built-in scene: a 0.1 m cube of water (1 kg), tilted 10°, dropped from 0.2 m onto a fixed floor, 3 s.
for exe in cmake/embed cmake/embed_static pc/embed pc/embed_static; do
  "$tmp/$exe" >"$tmp/${exe//\//-}.out" 2>"$tmp/${exe//\//-}.err"
  rc=$?
  # stderr holds nothing but the engine's counted warnings (e.g. a late onset: information, not failure)
  check "$exe runs the built-in scene" '[ $rc -eq 0 ] && ! grep -qv "^warning: [a-z_]* x [0-9]*$" "$tmp/${exe//\//-}.err"'
done
# the same engine built four ways gives the same bytes (determinism)
for out in cmake-embed_static pc-embed pc-embed_static; do
  check "$out prints what cmake/embed prints" 'cmp -s "$tmp/cmake-embed.out" "$tmp/$out.out"'
done
out=$tmp/cmake-embed.out
last=$(awk '$1 == "pose" {t = $2} END {print t}' "$out")
check "the run reaches t = 3 s" '[ "$last" = 3.000 ]'
# at rest on a face (whichever: the tilted cube lands on an edge and may tip over): the centre of mass at half
# the side above the floor to within 20 µm (the springs sag m g/(4 k), a few µm under 1 kg), and still
awk -v t="$last" '$1 == "pose" && $2 == t {print $6, sqrt($11*$11 + $12*$12 + $13*$13)}' "$out" >"$tmp/rest"
read -r z speed <"$tmp/rest"
check "the cube rests at z = 0.05 m ± 20 µm (z = $z)" 'awk -v z="$z" "BEGIN {exit !(z > 0.04998 && z < 0.05002)}"'
check "the cube is still: |v| < 1e-4 m/s (|v| = $speed)" 'awk -v s="$speed" "BEGIN {exit !(s < 1e-4)}"'
# four vertex–face contacts (a face's corners), normal +z; the floor carries the weight m g = 9.81 N
contacts=$(awk -v t="$last" '$1 == "contact" && $2 == t && $5 == "VF" && $11 > 0.999999' "$out" | wc -l)
check "four VF contacts with normal +z at rest ($contacts)" '[ "$contacts" -eq 4 ]'
fz=$(awk -v t="$last" '$1 == "load" && $2 == t && $3 == "block" {print $6}' "$out")
check "the contact forces on the cube sum to m g = 9.81 N ± 0.01 N (Fz = $fz)" \
  'awk -v f="$fz" "BEGIN {exit !(f > 9.80 && f < 9.82)}"'
fxy=$(awk -v t="$last" '$1 == "load" && $2 == t && $3 == "block" {print sqrt($4*$4 + $5*$5)}' "$out")
check "no net horizontal contact force at rest: < 1e-3 N ($fxy)" 'awk -v f="$fxy" "BEGIN {exit !(f < 1e-3)}"'

# A scene file: floor_slide.scene launches the cube at 1.5 m/s with μ = 0.5; it stops after
# v²/(2 μ g) = 0.22936 m. Within 1 mm; the installed CLI computes the same run.
"$tmp/cmake/embed" "$src/cases/user/floor_slide.scene" >"$tmp/slide.out" 2>&1
rc=$?
check "embed runs a scene file" '[ $rc -eq 0 ]'
x=$(awk '$1 == "pose" {x = $4} END {print x}' "$tmp/slide.out")
check "the slide stops at x = 0.22936 m ± 1 mm (x = $x)" 'awk -v x="$x" "BEGIN {exit !(x > 0.22836 && x < 0.23036)}"'
# The README's 20-line example (examples/embed/minimal.c) on the same scene: at its last sample the 1 kg cube
# rests, so its contacts' normal forces sum to m g = 9.81 N (± 0.01 N: the springs' ringing has died out).
"$tmp/cmake/embed_minimal" "$src/cases/user/floor_slide.scene" >"$tmp/minimal.out" 2>&1
rc=$?
fsum=$(awk '{t[NR] = $1; f[NR] = $(NF - 1)} END {for (i = 1; i <= NR; i++) if (t[i] == t[NR]) s += f[i]; print s}' \
  "$tmp/minimal.out")
check "the README's example runs and its last contacts carry m g = 9.81 N ± 0.01 N ($fsum)" \
  '[ $rc -eq 0 ] && awk -v f="$fsum" "BEGIN {exit !(f > 9.80 && f < 9.82)}"'
run_pd_installed() { "$prefix/bin/polydyn" "$@" >"$tmp/cli.out" 2>"$tmp/cli.err"; rc=$?; }
run_pd_installed run "$src/cases/user/floor_slide.scene" --out "$tmp/slide-run"
check "installed polydyn run works outside the build tree" '[ $rc -eq 0 ] && [ -f "$tmp/slide-run/summary.json" ]'
xcli=$(tail -n 1 "$tmp/slide-run/trajectory.csv" | cut -d, -f3)
check "polydyn run ends where embed ends: |dx| < 1e-8 m ($xcli, $x)" \
  'awk -v a="$xcli" -v b="$x" "BEGIN {d = a - b; exit !(d < 1e-8 && d > -1e-8)}"'
run_pd_installed check "$src/cases/user/floor_slide.scene"
check "installed polydyn check works" '[ $rc -eq 0 ] && grep -q block "$tmp/cli.out"'

echo "$passed passed, $failed failed"
[ $failed -eq 0 ]
