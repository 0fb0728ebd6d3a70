#!/usr/bin/env bash
# Instructions per ray and per pixel sample of each integrator on the benchmark scenes (bench/scenes.sh),
# counted by valgrind's callgrind. Wall-clock figures on a shared machine move by 5-50 % from run to
# run (docs/benchmarks.md); instruction counts of a one-thread render with a fixed seed do not (two
# runs differ by less than 0.02 %), so a change of a percent in what the renderer does per ray shows,
# and a regression shows as a step in bench/results/instructions.csv (plot it with
# bench/plot-history.py --csv bench/results/instructions.csv). They do not see cache misses
# or stalls: a change that moves memory traffic needs alternated wall-clock pairs.
#
# For each (scene, integrator) two one-thread renders with seed 1 are counted whole: RES x RES with
# PASSES passes (sppm: iterations), and 8x8 with one pass. Parsing, plugin loading and the BVH build
# are the same in both; the difference is the rendering work of the extra samples, divided by the extra
# rays (the stats' `rays`) and by the extra pixel samples. Images are written as PFM: the EXR writer's
# libraries use RDTSCP, which valgrind 3.19 (Debian 12) cannot run. Under valgrind, libraries that
# choose their code by processor (Embree, glibc, the core's x86-64-v3 clones) see valgrind's virtual
# processor (AVX2, no AVX-512), so compare counts only between runs of this script.
#
# Usage: bench/instructions.sh [--scenes a,b] [--integrators path,bdpt,sppm] [--res N] [--passes N]
#                              [--no-history] [--keep DIR] [--build DIR]
#   --scenes       default: every scene of bench/scenes.sh
#   --integrators  default path,bdpt,sppm (lighttracing also works)
#   --res          image width and height of the counted render (default 64)
#   --passes       passes (sppm: iterations) of the counted render (default 4)
#   --no-history   do not append to bench/results/instructions.csv
#   --keep DIR     keep the stats, callgrind logs and the table in DIR (default: a temporary folder)
# Needs valgrind (apt-get install valgrind). About 2 minutes for the default 5 scenes x 3 integrators.
set -euo pipefail

root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
source "$root/bench/scenes.sh"
source "$root/bench/common.sh"

scenes=$(bench_scene_names | paste -sd, -)
integrators=path,bdpt,sppm
res=64
passes=4
history=1
keep=""
build="$root/build"
while [ $# -gt 0 ]; do
  case "$1" in
    --scenes) scenes="$2"; shift 2 ;;
    --integrators) integrators="$2"; shift 2 ;;
    --res) res="$2"; shift 2 ;;
    --passes) passes="$2"; shift 2 ;;
    --no-history) history=0; shift ;;
    --keep) keep="$2"; shift 2 ;;
    --build) build="$2"; shift 2 ;;
    -h|--help) sed -n '2,/^set -euo/p' "$0" | sed '$d; s/^# \{0,1\}//'; exit 0 ;;
    *) echo "instructions.sh: unknown option $1 (see --help)" >&2; exit 2 ;;
  esac
done
[[ "$res" =~ ^[1-9][0-9]*$ ]] && [ "$res" -gt 8 ] || { echo "instructions.sh: --res must be an integer above 8" >&2; exit 2; }
[[ "$passes" =~ ^[1-9][0-9]*$ ]] || { echo "instructions.sh: --passes must be a positive integer" >&2; exit 2; }
command -v valgrind > /dev/null || { echo "instructions.sh: needs valgrind (apt-get install valgrind)" >&2; exit 1; }
bench_prepare "$scenes" "$integrators" "$build" "$keep" penumbra-instructions
vg=$(valgrind --version)
echo "instructions.sh: $(echo $scene_list | wc -w) scenes x $(echo $integrator_list | wc -w) integrators," \
  "${res}x${res} x $passes passes minus 8x8 x 1; commit $commit ($arch build), $vg" >&2

# count NAME SCENE INTEGRATOR RES PASSES: one counted render; its stats go to $work/NAME.json and the
# instruction total to $work/NAME.ir.
count() {
  local name="$1" file="$2" integrator="$3" r="$4" p="$5"
  valgrind --tool=callgrind --callgrind-out-file=/dev/null \
    "$build/bin/penumbra" render "$file" --integrator "$integrator" --res "${r}x${r}" --spp "$p" --threads 1 \
    --seed 1 -q -o "$work/$name.pfm" --stats "$work/$name.json" > "$work/$name.log" 2>&1 ||
    { tail -20 "$work/$name.log" >&2; echo "instructions.sh: $name failed" >&2; exit 1; }
  awk '/Collected :/ { print $NF }' "$work/$name.log" > "$work/$name.ir"
  [ -s "$work/$name.ir" ] || { echo "instructions.sh: no instruction count in $work/$name.log" >&2; exit 1; }
}

for s in $scene_list; do
  file="$root/$(bench_scene_file "$s")"
  for i in $integrator_list; do
    echo "instructions.sh: $s $i" >&2
    count "$s-$i-big" "$file" "$i" "$res" "$passes"
    count "$s-$i-small" "$file" "$i" 8 1
  done
done

"$py" - "$work" "$scene_list" "$integrator_list" "$res" "$passes" "$date_iso" "$commit" "$cpu" "$arch" "$vg" \
  "$([ "$history" = 1 ] && echo "$root/bench/results/instructions.csv")" <<'EOF' | tee "$work/table.md"
import csv, json, os, sys
work, scenes, integrators, res, passes, date, commit, cpu, arch, vg, history = sys.argv[1:12]
rows = []
for s in scenes.split():
    for i in integrators.split():
        def load(kind):
            with open(os.path.join(work, f"{s}-{i}-{kind}.json")) as f:
                stats = json.load(f)
            with open(os.path.join(work, f"{s}-{i}-{kind}.ir")) as f:
                ir = int(f.read().split()[0].replace(",", ""))
            return ir, stats["rays"], stats["pixels"] * stats["spp"]
        ir_b, rays_b, samples_b = load("big")
        ir_s, rays_s, samples_s = load("small")
        ir, rays, samples = ir_b - ir_s, rays_b - rays_s, samples_b - samples_s
        rows.append((s, i, ir, rays, samples, ir / rays if rays else float("nan"), ir / samples))
print(f"| scene | integrator | instructions | rays | pixel samples | per ray | per sample |")
print(f"|---|---|---|---|---|---|---|")
for s, i, ir, rays, samples, per_ray, per_sample in rows:
    print(f"| {s} | {i} | {ir:,} | {rays:,} | {samples:,} | {per_ray:,.0f} | {per_sample:,.0f} |")
if history:
    new = not os.path.exists(history)
    with open(history, "a", newline="") as f:
        w = csv.writer(f)
        if new:
            w.writerow(["date", "commit", "cpu", "arch", "valgrind", "scene", "integrator", "res", "passes",
                        "instructions", "rays", "pixel_samples", "instructions_per_ray", "instructions_per_sample"])
        for s, i, ir, rays, samples, per_ray, per_sample in rows:
            w.writerow([date, commit, cpu, arch, vg, s, i, res, passes, ir, rays, samples,
                        f"{per_ray:.1f}", f"{per_sample:.1f}"])
EOF
