#!/usr/bin/env bash
# Regenerates docs/convergence.md and its plots: for each bundled scene, `penumbra converge` renders
# every available integrator:sampler configuration progressively against a fresh reference, then
# scripts/plot-convergence.py draws relMSE versus time and scripts/write-convergence-doc.py writes
# the tables. Settings (environment variables): TIME seconds per run, RUNS runs per configuration,
# REF seconds for the reference, RES resolution, SNAPSHOTS per run, SCENES to limit the scenes.
# An empty reference configuration leaves the choice to `penumbra converge` (an unbiased integrator
# not compared, else one half each of two). The defaults take about 50 minutes on 2 cores and must
# run on a quiet machine (the figures are times); TIME=4 RUNS=3 REF=30 gives a quick look.
set -euo pipefail
cd "$(dirname "$0")/.."
TIME=${TIME:-10}
RUNS=${RUNS:-8}
REF=${REF:-180}
RES=${RES:-128x96}
SNAPSHOTS=${SNAPSHOTS:-7}
scripts/build.sh >&2
bin=build/bin/penumbra
plugins=$($bin plugins 2>/dev/null || true)
has() { grep -q "$1 '$2'" <<<"$plugins"; }

# name | scene file | configurations (only those whose plugins exist are run) | reference configuration
studies=(
  "cornell-box|scenes/cornell-box/scene.pbrt|path:independent path:sobol path:halton bdpt:sobol sppm:halton|"
  "environment|scenes/environment/scene.pbrt|path:independent path:sobol bdpt:sobol sppm:halton|"
  "caustics|scenes/caustics/scene.pbrt|path:sobol bdpt:sobol bdpt/hrr=true:sobol sppm:halton|"
  "sppm-caustics|scenes/sppm-caustics/scene.pbrt|path:sobol bdpt:sobol sppm:halton|sppm:halton"
  "window|scenes/window/scene.pbrt|path:sobol bdpt:sobol bdpt/hrr=true:sobol bdpt/probconnect=true:sobol bdpt/hrr=true/probconnect=true:sobol|"
)
out=docs/convergence
mkdir -p "$out"
# Fresh references for every study run: the converge cache is keyed by scene and settings, not by the
# renderer build, and a published study must not reuse a reference an older build made.
refcache=$(mktemp -d "${TMPDIR:-/tmp}/penumbra-study-references.XXXXXX")
trap 'rm -rf "$refcache"' EXIT
for study in "${studies[@]}"; do
  IFS='|' read -r name scene configs refconfig <<<"$study"
  if [ -n "${SCENES:-}" ] && ! grep -qw "$name" <<<"$SCENES"; then continue; fi
  [ -f "$scene" ] || { echo "skipping $name: $scene does not exist yet" >&2; continue; }
  list=()
  # A configuration may set integrator parameters: integrator[/NAME=VALUE...][:sampler].
  for c in $configs; do has integrator "${c%%[:/]*}" && list+=("$c"); done
  refargs=()
  if [ -n "$refconfig" ]; then
    has integrator "${refconfig%%[:/]*}" || refconfig="path:sobol"
    refargs=(--reference-config "$refconfig")
  fi
  joined=$(IFS=,; echo "${list[*]}")
  echo "== $name: $joined (reference ${refconfig:-the converge default}, ${REF}s)" >&2
  PENUMBRA_REFERENCE_CACHE="$refcache" $bin converge "$scene" --configs "$joined" --make-reference "$REF" "${refargs[@]}" \
    --time "$TIME" --runs "$RUNS" --snapshots "$SNAPSHOTS" --res "$RES" -o "$out/$name"
  /usr/bin/python3 scripts/plot-convergence.py "$out/$name" "$name"
  rm -f "$out/$name"/reference*.exr
done
/usr/bin/python3 scripts/write-convergence-doc.py "$out" "TIME=$TIME RUNS=$RUNS REF=$REF RES=$RES SNAPSHOTS=$SNAPSHOTS" > docs/convergence.md
echo "wrote docs/convergence.md" >&2
