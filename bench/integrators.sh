#!/usr/bin/env bash
# Equal-time benchmark of the integrators on the benchmark scenes (bench/scenes.sh): each
# (scene, integrator) renders for a fixed time at the scene's resolution, and the table gives
#   passes     samples per pixel (path, bdpt, lighttracing) or iterations (sppm) completed
#   passes/s   passes per second of rendering (parsing and BVH build excluded)
#   Mrays/s    every ray the integrator traced, per second
#   relMSE     mean over pixels and channels of (I - R)^2 / (R^2 + 0.01) against the stored reference
#              bench/references/<scene>.exr (bench/make-references.sh); median [min, max] over --runs
#   vs Embree  path tracer's Mrays/s over raw Embree's on the same scene and thread count
#              (penumbra-bench-render --raw-only: incoherent closest-hit and shadow rays, no shading),
#              measured just before and just after the path tracer's runs and averaged, so that a
#              drift of the machine during the renders moves both sides of the ratio alike
# and appends one line per (scene, integrator) to bench/results/history.csv (plot it with
# bench/plot-history.py).
#
# Usage: bench/integrators.sh [--time S] [--scenes a,b] [--integrators path,bdpt,sppm] [--runs N]
#                             [--threads N] [--quick] [--no-history] [--keep DIR] [--build DIR]
#   --time         seconds per render (default 10)
#   --scenes       default: every scene of bench/scenes.sh
#   --integrators  default path,bdpt,sppm (lighttracing also works)
#   --runs         independent runs per (scene, integrator), seeds 1..N (default 1)
#   --threads      worker threads (default 2)
#   --quick        2 s per render, 1 run, 500,000 raw Embree rays, no history line: a smoke test
#   --no-history   do not append to bench/results/history.csv
#   --keep DIR     keep the images, stats and table in DIR (default: a temporary folder, removed)
set -euo pipefail

root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
source "$root/bench/scenes.sh"
source "$root/bench/common.sh"

time_budget=10
scenes=$(bench_scene_names | paste -sd, -)
integrators=path,bdpt,sppm
runs=1
threads=2
quick=0
history=1
keep=""
build="$root/build"
rays=2000000
time_given=0
runs_given=0
while [ $# -gt 0 ]; do
  case "$1" in
    --time) time_budget="$2"; time_given=1; shift 2 ;;
    --scenes) scenes="$2"; shift 2 ;;
    --integrators) integrators="$2"; shift 2 ;;
    --runs) runs="$2"; runs_given=1; shift 2 ;;
    --threads) threads="$2"; shift 2 ;;
    --quick) quick=1; shift ;;
    --no-history) history=0; shift ;;
    --keep) keep="$2"; shift 2 ;;
    --build) build="$2"; shift 2 ;;
    -h|--help) sed -n '2,/^set -euo/p' "$0" | sed '$d; s/^# \{0,1\}//'; exit 0 ;;
    *) echo "integrators.sh: unknown option $1 (see --help)" >&2; exit 2 ;;
  esac
done
if [ "$quick" = 1 ]; then
  [ "$time_given" = 1 ] || time_budget=2
  [ "$runs_given" = 1 ] || runs=1
  rays=500000
  history=0
fi
[[ "$runs" =~ ^[1-9][0-9]*$ ]] || { echo "integrators.sh: --runs must be a positive integer" >&2; exit 2; }
bench_prepare "$scenes" "$integrators" "$build" "$keep" penumbra-bench
load=$(bench_loadavg)
echo "integrators.sh: $(echo $scene_list | wc -w) scenes x $(echo $integrator_list | wc -w) integrators x $runs runs" \
  "x ${time_budget} s, $threads threads; commit $commit ($arch build); load average $load on $(nproc) cores" >&2

# raw_embree SCENE OUTPUT: raw Embree's rates on the scene into $work/SCENE/OUTPUT.
raw_embree() {
  echo "integrators.sh: $1: raw Embree ($rays rays)" >&2
  "$build/bin/penumbra-bench-render" --scene "$root/$(bench_scene_file "$1")" --raw-only --json \
    --threads "$threads" --rays "$rays" > "$work/$1/$2"
}

for s in $scene_list; do
  file="$root/$(bench_scene_file "$s")"
  mkdir -p "$work/$s"
  for i in $integrator_list; do
    if [ "$i" = path ]; then raw_embree "$s" embree.json; fi
    for ((k = 1; k <= runs; ++k)); do
      extra=$(bench_integrator_params "$i")
      # sppm draws its photons from streams of its own seed; the sampler's seed drives only the camera.
      [ "$i" = sppm ] && extra="$extra --param seed=$k"
      echo "integrators.sh: $s $i run $k/$runs (${time_budget} s)" >&2
      # shellcheck disable=SC2086
      "$build/bin/penumbra" render "$file" --integrator "$i" $extra --time "$time_budget" --threads "$threads" \
        --seed "$k" -q -o "$work/$s/$i-$k.exr" --stats "$work/$s/$i-$k.json" 2> "$work/$s/$i-$k.log" ||
        { cat "$work/$s/$i-$k.log" >&2; echo "integrators.sh: $s $i run $k failed" >&2; exit 1; }
      ref="$root/bench/references/$s.exr"
      if [ -f "$ref" ]; then
        "$build/bin/penumbra-bench-image-errors" "$work/$s/$i-$k.exr" "$ref" > "$work/$s/$i-$k.errors.json" ||
          echo '{"relmse": null, "error": "penumbra-bench-image-errors failed"}' > "$work/$s/$i-$k.errors.json"
      fi
    done
    if [ "$i" = path ]; then raw_embree "$s" embree-after.json; fi
  done
done

"$py" "$root/bench/summarise.py" --work "$work" --scenes "$(echo $scene_list)" --integrators "$integrators" \
  --runs "$runs" --time "$time_budget" --threads "$threads" --date "$date_iso" --commit "$commit" \
  --nproc "$(nproc)" --cpu "$cpu" --load "$load" --arch "$arch" --references "$root/bench/references" \
  $([ "$history" = 1 ] && echo --history "$root/bench/results/history.csv") | tee "$work/table.md"
