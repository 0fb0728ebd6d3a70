#!/usr/bin/env bash
# Two builds of Penumbra on the same render, alternated pair by pair: what a change does to render
# time (fixed samples) or to error at equal time (--time). On a shared machine one render's speed
# moves by 10-30 % from minute to minute, so single runs, and even two batches run one after the
# other, say little; the two renders of a pair run back to back (which goes first alternates), and
# the figure is the median of the pairs' ratios, new over base, with a distribution-free interval of
# at least 95 % for that median (bench/pair_stats.py; it needs 6 pairs or more) and their range. A
# change is decided only when the interval lies on one side of 1. Pair i renders with --seed i.
#
# Copy the base build aside before rebuilding (cp -a build /tmp/base), then:
#   bench/ab-builds.sh --base /tmp/base [--new build] [--scene FILE] [--integrator NAME] [--res N]
#                      [--spp N | --time S] [--pairs N] [--threads N] [--reference EXR] [--keep DIR]
#   --new         the build under test (default: build/ of this checkout)
#   --scene       default: the bundled Cornell box
#   --integrator  default: the scene's own
#   --res         square film resolution (default 128)
#   --spp         samples per pixel (default 32); compares render seconds
#   --time        seconds per render instead: compares passes per second, and relMSE against --reference
#   --pairs       default 30 (on this project's 2-core machine the median of 30 pairs of a
#                 one-second render moves by about 2 % between repetitions)
#   --threads     default 1; one thread is pinned to processor 0 (taskset), more are not pinned
#   --reference   an EXR of the same scene at --res (bench/make-references.sh makes them at the
#                 scene's resolution); with --time, relMSE ratios are printed too
#   --keep DIR    keep the CSV of every render in DIR
# Example (what the fifteenth session measured by hand, docs/benchmarks.md):
#   bench/ab-builds.sh --base /tmp/base --integrator path --res 128 --spp 32 --pairs 30
set -euo pipefail

root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
source "$root/bench/common.sh"

base=""
new="$root/build"
scene="$root/scenes/cornell-box/scene.pbrt"
integrator=""
res=128
spp=32
time_budget=""
pairs=30
threads=1
reference=""
keep=""
while [ $# -gt 0 ]; do
  case "$1" in
    --base) base="$2"; shift 2 ;;
    --new) new="$2"; shift 2 ;;
    --scene) scene="$2"; shift 2 ;;
    --integrator) integrator="$2"; shift 2 ;;
    --res) res="$2"; shift 2 ;;
    --spp) spp="$2"; shift 2 ;;
    --time) time_budget="$2"; shift 2 ;;
    --pairs) pairs="$2"; shift 2 ;;
    --threads) threads="$2"; shift 2 ;;
    --reference) reference="$2"; shift 2 ;;
    --keep) keep="$2"; shift 2 ;;
    -h|--help) sed -n '2,/^set -euo/p' "$0" | sed '$d; s/^# \{0,1\}//'; exit 0 ;;
    *) echo "ab-builds.sh: unknown option $1 (see --help)" >&2; exit 2 ;;
  esac
done
[ -n "$base" ] || { echo "ab-builds.sh: --base DIR is required (a copy of the build before the change)" >&2; exit 2; }
for n in res spp pairs threads; do
  [[ "${!n}" =~ ^[1-9][0-9]*$ ]] || { echo "ab-builds.sh: --$n must be a positive whole number, not '${!n}'" >&2; exit 2; }
done
[ -z "$time_budget" ] || [[ "$time_budget" =~ ^[0-9]+([.][0-9]+)?$ ]] ||
  { echo "ab-builds.sh: --time must be a number of seconds, not '$time_budget'" >&2; exit 2; }
[ -f "$scene" ] || { echo "ab-builds.sh: --scene: no file '$scene'" >&2; exit 2; }
[ -z "$reference" ] || [ -f "$reference" ] || { echo "ab-builds.sh: --reference: no file '$reference'" >&2; exit 2; }
[ -z "$reference" ] || [ -n "$time_budget" ] ||
  { echo "ab-builds.sh: --reference goes with --time (error at equal time)" >&2; exit 2; }
bench_find_build "$new"
[ -x "$base/bin/penumbra" ] || { echo "ab-builds.sh: --base: no $base/bin/penumbra" >&2; exit 2; }
py=$(bench_python)
bench_work_dir "$keep" penumbra-ab
csv="$work/renders.csv"

pin=()
[ "$threads" = 1 ] && command -v taskset > /dev/null && pin=(taskset -c 0)
args=(--res "${res}x${res}" --threads "$threads" -q)
if [ -n "$time_budget" ]; then args+=(--time "$time_budget"); else args+=(--spp "$spp"); fi
[ -z "$integrator" ] || args+=(--integrator "$integrator")

echo "ab-builds.sh: $pairs pairs of $(basename "$scene"), ${res}x${res}, $([ -n "$time_budget" ] && echo "$time_budget s" || echo "$spp spp"), $threads thread(s); base $base, new $new" >&2
echo "pair,build,seconds,passes,relmse,load" > "$csv"
for pair in $(seq 1 "$pairs"); do
  order="base new"
  [ $((pair % 2)) = 0 ] && order="new base"
  for which in $order; do
    dir=$base
    [ "$which" = new ] && dir=$new
    load=$(bench_loadavg)
    "${pin[@]}" "$dir/bin/penumbra" render "$scene" "${args[@]}" --seed "$pair" -o "$work/$which.exr" \
      --stats "$work/$which.json" 2> "$work/$which.log" ||
      { cat "$work/$which.log" >&2; echo "ab-builds.sh: the $which build failed (pair $pair)" >&2; exit 1; }
    rel=""
    [ -z "$reference" ] || rel=$("$new/bin/penumbra-bench-image-errors" "$work/$which.exr" "$reference" |
                                 "$py" -c "import json, sys; print(json.load(sys.stdin)['relmse'])")
    "$py" -c "import json, sys; d = json.load(open(sys.argv[1])); \
print(f\"{sys.argv[2]},{sys.argv[3]},{d['seconds']},{d['samples_per_pixel']},{sys.argv[4]},{sys.argv[5]}\")" \
      "$work/$which.json" "$pair" "$which" "$rel" "$load" >> "$csv"
  done
done

"$py" - "$csv" "$root/bench" "${time_budget:+time}" <<'EOF'
import csv, statistics, sys
sys.path.insert(0, sys.argv[2])
from pair_stats import describe_ratios
rows = list(csv.DictReader(open(sys.argv[1])))
equal_time = sys.argv[3] == "time"
pairs = {}
for r in rows:
    pairs.setdefault(r["pair"], {})[r["build"]] = r
full = [p for p in pairs.values() if "base" in p and "new" in p]
measures = [("passes/s", lambda r: float(r["passes"]) / float(r["seconds"]))] if equal_time else \
           [("render seconds", lambda r: float(r["seconds"]))]
if equal_time and all(r["relmse"] for r in rows):
    measures.append(("relMSE", lambda r: float(r["relmse"])))
for name, f in measures:
    base = statistics.median(f(p["base"]) for p in full)
    new = statistics.median(f(p["new"]) for p in full)
    ratios = [f(p["new"]) / f(p["base"]) for p in full]
    print(f"{name}: base {base:.4g}, new {new:.4g}; pairs new / base: {describe_ratios(ratios)}, {len(ratios)} pairs")
EOF
[ -z "$keep" ] || echo "ab-builds.sh: every render's figures are in $csv" >&2
