#!/usr/bin/env bash
# Renders the reference image of each benchmark scene of bench/integrators.sh to
# bench/references/<scene>.exr (half-float RGB EXR, the scene's own resolution) with a sidecar
# bench/references/<scene>.json (integrator, time, samples, machine, commit, noise floor).
#
# Each reference is two independent renders of half the budget each (seeds 1000001 and 1000002,
# never used by the benchmark's runs), combined weighted by their sample counts (w1, w2). Their
# difference estimates the reference's own variance, about w1 w2 (A - B)^2 per pixel; relmse_floor,
# its mean over (R^2 + 0.01), is the relMSE a perfect image would still show against this reference
# (every relMSE the benchmark measures includes it), and relmse_own_error, over the square of each
# pixel's neighbours' mean instead, estimates the reference's own relMSE against the truth.
# The integrator is the scene's entry in bench/scenes.sh: path tracing, or bdpt where path tracing
# misses light (the point light's caustic through the glass sphere).
#
# Usage: bench/make-references.sh [--time SECONDS] [--threads N] [--scenes a,b,...] [--build DIR] [--out DIR]
#   --time     wall-clock budget per scene (default 3600: the figure the stored references are meant
#              to have; run it on a quiet machine)
#   --threads  worker threads (default: all cores, nproc)
#   --out      folder to write to (default bench/references; bench/integrators.sh reads only that one)
set -euo pipefail

root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
source "$root/bench/scenes.sh"
source "$root/bench/common.sh"

time_budget=3600
threads=$(nproc)
scenes=$(bench_scene_names | paste -sd, -)
build="$root/build"
out="$root/bench/references"
while [ $# -gt 0 ]; do
  case "$1" in
    --time) time_budget="$2"; shift 2 ;;
    --threads) threads="$2"; shift 2 ;;
    --scenes) scenes="$2"; shift 2 ;;
    --build) build="$2"; shift 2 ;;
    --out) out="$2"; shift 2 ;;
    -h|--help) sed -n '2,/^set -euo/p' "$0" | sed '$d; s/^# \{0,1\}//'; exit 0 ;;
    *) echo "make-references: unknown option $1 (see --help)" >&2; exit 2 ;;
  esac
done
scene_list=$(bench_check_scenes "$scenes")
bench_find_build "$build"
command -v oiiotool >/dev/null || { echo "make-references: oiiotool missing (scripts/install-deps.sh installs openimageio-tools)" >&2; exit 1; }
py=$(bench_python)

mkdir -p "$out"
work=$(mktemp -d "${TMPDIR:-/tmp}/penumbra-refs.XXXXXX")
trap 'rm -rf "$work"' EXIT
half=$("$py" -c "print($time_budget / 2)")
commit=$(bench_commit "$root")

for s in $scene_list; do
  file="$root/$(bench_scene_file "$s")"
  integrator=$(bench_scene_reference_integrator "$s")
  for h in 1 2; do
    seed=$((1000000 + h))
    echo "make-references: $s half $h/2 ($integrator, ${half} s, $threads threads, seed $seed)" >&2
    "$build/bin/penumbra" render "$file" --integrator "$integrator" --time "$half" --threads "$threads" \
      --seed "$seed" -q -o "$work/$s-$h.exr" --stats "$work/$s-$h.json"
  done
  read -r spp1 spp2 < <("$py" -c "import json,sys; print(*(json.load(open(f))['spp'] for f in sys.argv[1:]))" \
    "$work/$s-1.json" "$work/$s-2.json")
  w1=$("$py" -c "print($spp1 / ($spp1 + $spp2))")
  w2=$("$py" -c "print($spp2 / ($spp1 + $spp2))")
  oiiotool "$work/$s-1.exr" --mulc "$w1" "$work/$s-2.exr" --mulc "$w2" --add -o "$work/$s-ref.exr"
  oiiotool "$work/$s-ref.exr" -d half --compression piz -o "$out/$s.exr"
  # The reference's variance per pixel is about w1 w2 (A - B)^2. Over (R^2 + 0.01) its mean is the
  # floor, the reference's own share of any relMSE measured against it; over the square of each
  # pixel's neighbours' mean it estimates the reference's own error (docs/algorithms.md).
  errors=$("$build/bin/penumbra-bench-image-errors" --reference-noise "$work/$s-1.exr" "$spp1" "$work/$s-2.exr" "$spp2")
  "$py" - "$out/$s.json" "$s" "$(bench_scene_file "$s")" "$integrator" "$time_budget" "$threads" \
      "$commit" "$(nproc)" "$(bench_cpu_model)" "$(bench_loadavg)" "$errors" "$work/$s-1.json" "$work/$s-2.json" \
      "$out/$s.exr" <<'EOF'
import datetime, json, os, sys
(path, scene, file, integrator, budget, threads, commit, nproc, cpu, load, errors, s1, s2, exr) = sys.argv[1:]
st = [json.load(open(s1)), json.load(open(s2))]
e = json.loads(errors)
meta = {
    "scene": scene, "file": file, "integrator": integrator,
    "time_budget": float(budget), "render_seconds": sum(x["seconds"] for x in st),
    "spp": sum(x["spp"] for x in st), "threads": int(threads), "seeds": [x["seed"] for x in st],
    "nonfinite_samples": sum(x["nonfinite_samples"] for x in st),
    "resolution": [e["width"], e["height"]],
    "relmse_floor": e["floor"],
    "relmse_floor_note": "mean over pixels and channels of w1 w2 (A - B)^2 / (R^2 + 0.01): the reference's "
                         "own noise in relMSE units, included in every relMSE measured against it",
    "relmse_own_error": e["own_error"],
    "relmse_own_error_note": "mean over pixels and channels of w1 w2 (A - B)^2 / (m^2 + 0.01), m the mean of "
                             "R over the pixel's neighbours: the reference's own relMSE against the truth "
                             "(docs/algorithms.md, \"A reference's own error\")",
    "date": datetime.datetime.now().astimezone().isoformat(timespec="seconds"),
    "commit": commit, "nproc": int(nproc), "cpu": cpu, "loadavg_at_start": load,
    "file_bytes": os.path.getsize(exr), "format": "half-float RGB EXR, PIZ",
}
json.dump(meta, open(path, "w"), indent=2)
open(path, "a").write("\n")
print(f"make-references: {scene}: {meta['spp']} spp in {meta['render_seconds']:.0f} s ({integrator}), "
      f"relMSE floor {meta['relmse_floor']:.3g}, own error {meta['relmse_own_error']:.3g}, "
      f"{meta['file_bytes'] / 1e6:.2f} MB -> {exr}", file=sys.stderr)
EOF
done
