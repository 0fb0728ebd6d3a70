#!/usr/bin/env bash
# Penumbra against SmallVCM (Davidovic and Georgiev's minimal renderer; nothing of it is in this
# repository) on the three cornell-spheres scenes, alternated cell by cell: each SmallVCM render is
# followed at once by Penumbra's render of the same cell, so both see the same state of the machine.
# For each cell (scene x algorithm: pt/path, bpt/bdpt, ppm/sppm) it prints the median over runs of
#   passes/s  SmallVCM: iterations over its process's wall time (it finishes the iteration it began,
#             so the overshoot is counted fairly); Penumbra: passes over its rendering seconds
#   relMSE    both images against bench/references/<scene>.exr (penumbra-bench-image-errors)
# and the ratios Penumbra / SmallVCM: of the medians, and per run, of each SmallVCM render and the
# Penumbra render after it (the median of those pairs, a distribution-free interval of at least 95 %
# for that median from the pairs' order statistics, which needs 6 runs or more, and their range). A
# cell is decided only when its interval lies on one side of 1. docs/benchmarks.md,
# "Against SmallVCM on the same machine", says how SmallVCM must be prepared: three scene
# configurations added as its scenes 4, 5 and 6 (both small spheres and a diffuse floor under the
# ceiling light, the point light and the background light) and its iteration count printed as
# "Iterations: N". Build both the same way (both portable, or both -march=native): the flag
# matters more to SmallVCM (same section).
#
# Usage: bench/vs-smallvcm.sh --smallvcm BIN [--runs N] [--time S] [--threads N] [--algorithms pt,bpt,ppm]
#                             [--scenes area,point,env] [--first-seed N] [--pause S] [--keep DIR] [--build DIR]
#   --smallvcm    the SmallVCM binary (required)
#   --runs        runs per cell (default 3); Penumbra's seed is the run number, SmallVCM's seeds are fixed
#   --first-seed  the first run's number (default 1): the seeds are N to N + runs - 1, so a batch that
#                 starts past an earlier batch's last seed adds independent samples instead of
#                 rendering the same images again
#   --time        seconds of wall time per render (default 10); SmallVCM's -t is processor time summed
#                 over its threads, so it is given time x threads
#   --pause       seconds of idle before each render (default 3), so one render's tail does not slow the next
#   --keep DIR    keep images, logs and the CSV of every render in DIR (default: a temporary folder)
set -euo pipefail

root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
source "$root/bench/common.sh"

smallvcm=""
runs=3
first_seed=1
time_budget=10
threads=2
algorithms=pt,bpt,ppm
scenes=area,point,env
pause=3
keep=""
build="$root/build"
while [ $# -gt 0 ]; do
  case "$1" in
    --smallvcm) smallvcm="$2"; shift 2 ;;
    --runs) runs="$2"; shift 2 ;;
    --first-seed) first_seed="$2"; shift 2 ;;
    --time) time_budget="$2"; shift 2 ;;
    --threads) threads="$2"; shift 2 ;;
    --algorithms) algorithms="$2"; shift 2 ;;
    --scenes) scenes="$2"; shift 2 ;;
    --pause) pause="$2"; shift 2 ;;
    --keep) keep="$2"; shift 2 ;;
    --build) build="$2"; shift 2 ;;
    -h|--help) sed -n '2,/^set -euo/p' "$0" | sed '$d; s/^# \{0,1\}//'; exit 0 ;;
    *) echo "vs-smallvcm.sh: unknown option $1 (see --help)" >&2; exit 2 ;;
  esac
done
[ -n "$smallvcm" ] || { echo "vs-smallvcm.sh: --smallvcm BIN is required (see --help)" >&2; exit 2; }
[ -x "$smallvcm" ] || { echo "vs-smallvcm.sh: --smallvcm: '$smallvcm' is not an executable file" >&2; exit 2; }
smallvcm=$(cd "$(dirname "$smallvcm")" && pwd)/$(basename "$smallvcm")
for option in runs:"$runs" first-seed:"$first_seed" time:"$time_budget" threads:"$threads"; do
  [[ "${option#*:}" =~ ^[1-9][0-9]*$ ]] || { echo "vs-smallvcm.sh: --${option%%:*} must be a positive integer" >&2; exit 2; }
done
[[ "$pause" =~ ^[0-9]+$ ]] || { echo "vs-smallvcm.sh: --pause must be a whole number of seconds" >&2; exit 2; }
command -v oiiotool >/dev/null || { echo "vs-smallvcm.sh: needs oiiotool (Debian: openimageio-tools)" >&2; exit 1; }
bench_find_build "$build"
py=$(bench_python)

declare -A scene_id=([area]=4 [point]=5 [env]=6)
declare -A integrator=([pt]=path [bpt]=bdpt [ppm]=sppm)
for s in ${scenes//,/ }; do
  [ -n "${scene_id[$s]:-}" ] || { echo "vs-smallvcm.sh: --scenes: unknown scene '$s' (area, point, env)" >&2; exit 2; }
done
for a in ${algorithms//,/ }; do
  [ -n "${integrator[$a]:-}" ] || { echo "vs-smallvcm.sh: --algorithms: unknown '$a' (pt, bpt, ppm)" >&2; exit 2; }
done

bench_work_dir "$keep" penumbra-vs-smallvcm
csv="$work/renders.csv"
echo "renderer,scene,algorithm,run,passes,seconds,relmse,load" > "$csv"
echo "vs-smallvcm.sh: $runs runs (seeds $first_seed-$((first_seed + runs - 1))) x scenes $scenes x $algorithms, ${time_budget} s, $threads threads;" \
  "Penumbra $(bench_commit "$root") ($(bench_build_arch "$build") build)" >&2

relmse_of() {  # image, reference
  "$build/bin/penumbra-bench-image-errors" "$1" "$2" | "$py" -c "import json, sys; print(json.load(sys.stdin)['relmse'])"
}

for ((run = first_seed; run < first_seed + runs; ++run)); do
  for s in ${scenes//,/ }; do
    scene_file="$root/scenes/bench/cornell-spheres-$s.pbrt"
    ref="$root/bench/references/cornell-spheres-$s.exr"
    for a in ${algorithms//,/ }; do
      name="$s-$a-$run"
      echo "vs-smallvcm.sh: run $run: $s $a" >&2
      sleep "$pause"
      load=$(bench_loadavg)
      # SmallVCM writes its image into the working folder it is given by -o; run it inside $work.
      start=$(date +%s.%N)
      (cd "$work" && OMP_NUM_THREADS="$threads" "$smallvcm" -s "${scene_id[$s]}" -a "$a" -t $((time_budget * threads)) \
        -o "$name.hdr" > "$name.smallvcm.log" 2>&1) ||
        { cat "$work/$name.smallvcm.log" >&2; echo "vs-smallvcm.sh: SmallVCM failed on $name" >&2; exit 1; }
      wall=$("$py" -c "import sys; print(float(sys.argv[2]) - float(sys.argv[1]))" "$start" "$(date +%s.%N)")
      iterations=$(sed -n 's/^Iterations: *\([0-9]*\).*/\1/p' "$work/$name.smallvcm.log")
      [ -n "$iterations" ] ||
        { echo "vs-smallvcm.sh: SmallVCM printed no 'Iterations: N' (see --help for the edits it needs)" >&2; exit 1; }
      oiiotool "$work/$name.hdr" -d float -o "$work/$name.smallvcm.exr"
      echo "smallvcm,$s,$a,$run,$iterations,$wall,$(relmse_of "$work/$name.smallvcm.exr" "$ref"),$load" >> "$csv"

      sleep "$pause"
      load=$(bench_loadavg)
      extra=()
      [ "$a" = ppm ] && extra=(--param "seed=$run")  # sppm's photons follow its own seed
      "$build/bin/penumbra" render "$scene_file" --integrator "${integrator[$a]}" "${extra[@]}" --time "$time_budget" \
        --threads "$threads" --seed "$run" -q -o "$work/$name.penumbra.exr" --stats "$work/$name.json" \
        2> "$work/$name.penumbra.log" ||
        { cat "$work/$name.penumbra.log" >&2; echo "vs-smallvcm.sh: Penumbra failed on $name" >&2; exit 1; }
      read -r passes seconds < <("$py" -c "import json, sys; d = json.load(open(sys.argv[1])); \
print(d['samples_per_pixel'], d['seconds'])" "$work/$name.json")
      echo "penumbra,$s,$a,$run,$passes,$seconds,$(relmse_of "$work/$name.penumbra.exr" "$ref"),$load" >> "$csv"
    done
  done
done

"$py" - "$csv" "$root/bench" <<'EOF'
import csv, statistics, sys
sys.path.insert(0, sys.argv[2])
from pair_stats import describe_ratios
rows = list(csv.DictReader(open(sys.argv[1])))
names = {"pt": "path", "bpt": "bdpt", "ppm": "sppm"}

print("| scene | algorithm | SmallVCM passes/s | Penumbra passes/s | ratio | pairs: median [95 % interval] (range) "
      "| SmallVCM relMSE | Penumbra relMSE | ratio | pairs: median [95 % interval] (range) |")
print("|---|---|---|---|---|---|---|---|---|---|")
cells = []
for r in rows:
    if (r["scene"], r["algorithm"]) not in cells:
        cells.append((r["scene"], r["algorithm"]))
rate = lambda r: float(r["passes"]) / float(r["seconds"])
rel = lambda r: float(r["relmse"])
for scene, alg in cells:
    runs = {}
    for r in rows:
        if r["scene"] == scene and r["algorithm"] == alg:
            runs.setdefault(r["run"], {})[r["renderer"]] = r
    def med(renderer, f):
        return statistics.median(f(pair[renderer]) for pair in runs.values() if renderer in pair)
    # Each run's SmallVCM render and the Penumbra render right after it share the machine's state:
    # the median of their ratios, its interval and their range say how far a conclusion would move
    # on a rerun.
    def pairs(f):
        q = [f(p["penumbra"]) / f(p["smallvcm"]) for p in runs.values() if "penumbra" in p and "smallvcm" in p]
        return describe_ratios(q, digits=2)
    sv, pn = med("smallvcm", rate), med("penumbra", rate)
    svr, pnr = med("smallvcm", rel), med("penumbra", rel)
    print(f"| {scene} | {alg} / {names[alg]} | {sv:.2f} | {pn:.2f} | {pn / sv:.2f} | {pairs(rate)} "
          f"| {svr:.4g} | {pnr:.4g} | {pnr / svr:.2f} | {pairs(rel)} |")
EOF
echo "vs-smallvcm.sh: every render's figures are in $csv$([ -z "$keep" ] && echo ' (removed at exit; --keep DIR keeps them)')" >&2
