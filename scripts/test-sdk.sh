#!/usr/bin/env bash
# The installed SDK, end to end: installs build/ into a temporary prefix, builds
# examples/plugin-ambient-occlusion against that prefix alone (from a copy outside the source tree),
# and has the installed penumbra list and render it, finding it through $PENUMBRA_PLUGIN_PATH. When
# clang++ (or clang++-14) is available, the example is also built with it and the loader must refuse that build.
# Usage: scripts/test-sdk.sh [BUILD_DIR]   (default: build/, built first if missing)
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
build="${1:-$root/build}"
[ -f "$build/CMakeCache.txt" ] || "$root/scripts/build.sh"

tmp="$(mktemp -d)"
trap 'rm -rf "$tmp"' EXIT
prefix="$tmp/prefix"
fail() { echo "test-sdk: FAIL: $*" >&2; exit 1; }
step() { echo "test-sdk: $*" >&2; }

step "installing $build into $prefix"
cmake --install "$build" --prefix "$prefix" >/dev/null
for f in bin/penumbra lib/libpenumbra-core.so include/penumbra/plugin.h lib/cmake/Penumbra/PenumbraConfig.cmake \
         lib/penumbra/plugins/penumbra-integrator-path.so; do
  [ -e "$prefix/$f" ] || fail "the install has no $f"
done

generator=()
command -v ninja >/dev/null 2>&1 && generator=(-G Ninja)
cp -r "$root/examples/plugin-ambient-occlusion" "$tmp/example"
step "building the example against the installed SDK"
cmake -S "$tmp/example" -B "$tmp/example/build" "${generator[@]}" -DCMAKE_BUILD_TYPE=Release \
      -DCMAKE_PREFIX_PATH="$prefix" >"$tmp/configure.log" 2>&1 || { cat "$tmp/configure.log"; fail "configure"; }
cmake --build "$tmp/example/build" >"$tmp/build.log" 2>&1 || { cat "$tmp/build.log"; fail "build"; }

# No RUNPATH entry of the example plugin may be empty or relative (the loader would search the
# current folder); tests/loading_test.cpp checks the tree's own binaries.
runpath="$(readelf -d "$tmp/example/build/plugins/penumbra-integrator-ambientocclusion.so" |
           sed -n 's/.*Library \(runpath\|rpath\): \[\(.*\)\]/\2/p')"
[ -n "$runpath" ] || fail "the example plugin has no RUNPATH"
case ":$runpath:" in
  *::*) fail "the example plugin's RUNPATH '$runpath' has an empty entry" ;;
esac
IFS=: read -ra entries <<<"$runpath"
for e in "${entries[@]}"; do
  case "$e" in /*|'$ORIGIN'*) ;; *) fail "the example plugin's RUNPATH '$runpath' has the relative entry '$e'" ;; esac
done

penumbra="$prefix/bin/penumbra"
export PENUMBRA_PLUGIN_PATH="$tmp/example/build/plugins"
"$penumbra" plugins >"$tmp/plugins.txt" || fail "penumbra plugins reported errors"
grep -q "integrator 'ambientocclusion' (alias 'ao')" "$tmp/plugins.txt" || fail "penumbra plugins does not list the example"
grep -q "maxdistance" "$tmp/plugins.txt" && grep -q "cossample" "$tmp/plugins.txt" ||
  fail "penumbra plugins does not show the example's parameters"

step "rendering the example's scene"
"$penumbra" render "$tmp/example/scene.pbrt" -o "$tmp/ao.exr" --res 64x48 --stats "$tmp/stats.json" -q
grep -q '"integrator/ambientocclusion"' "$tmp/stats.json" || fail "the render did not use the example plugin"
# Ambient occlusion lies in [0, 1]: open floor near 1, the crease under the sphere near 0.
read -r min max avg < <(oiiotool "$tmp/ao.exr" --printstats 2>/dev/null |
  awk '/Stats Min/ {mn=$3} /Stats Max/ {mx=$3} /Stats Avg/ {av=$3} END {print mn, mx, av}')
awk -v mn="$min" -v mx="$max" -v av="$avg" 'BEGIN { exit !(mn < 0.3 && mx <= 1.0001 && mx > 0.9 && av > 0.5 && av < 0.99) }' ||
  fail "the image does not look like ambient occlusion (min $min, max $max, mean $avg)"

# Debian's clang-14 package (scripts/install-deps.sh) installs clang++-14; a plain clang++ may not exist.
clang=""
for c in clang++ clang++-14; do
  if command -v "$c" >/dev/null 2>&1; then clang="$c"; break; fi
done
if grep -q '^CMAKE_CXX_COMPILER:.*clang' "$build/CMakeCache.txt"; then
  step "the runtime itself was built with clang: the other-compiler check is not applicable"
elif [ -z "$clang" ]; then
  fail "no clang++ or clang++-14 found (scripts/install-deps.sh installs clang-14): the other-compiler refusal cannot be checked"
else
  step "building the example with $clang: the loader must refuse it"
  cmake -S "$tmp/example" -B "$tmp/clang" "${generator[@]}" -DCMAKE_CXX_COMPILER="$clang" \
        -DCMAKE_PREFIX_PATH="$prefix" >"$tmp/clang.log" 2>&1 || { cat "$tmp/clang.log"; fail "clang configure"; }
  grep -q "will refuse" "$tmp/clang.log" || fail "configuring with another compiler gave no warning"
  if cmake --build "$tmp/clang" >>"$tmp/clang.log" 2>&1; then
    if PENUMBRA_PLUGIN_PATH="$tmp/clang/plugins" "$penumbra" render "$tmp/example/scene.pbrt" -o "$tmp/x.exr" -q \
         2>"$tmp/refused.txt"; then
      fail "the loader accepted a plugin built by clang++"
    fi
    grep -q "penumbra-integrator-ambientocclusion.so was built with compiler 'clang" "$tmp/refused.txt" ||
      { cat "$tmp/refused.txt"; fail "the refusal does not name the plugin and its compiler"; }
  else
    cat "$tmp/clang.log"
    fail "$clang could not build the example; the refusal was not checked"
  fi
fi
step "ok"
