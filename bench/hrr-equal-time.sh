#!/usr/bin/env bash
# Equal-time comparison on scenes/gdg-caustic (a caustic seen in a rough metal plate: glossy-diffuse-
# specular-light paths) of path tracing, plain bdpt, bdpt with hierarchical Russian roulette (hrr)
# with and without probabilistic connections, and SPPM. `penumbra converge` renders every
# configuration RUNS times for TIME seconds against one long reference and writes results.csv and
# summary.json (relMSE versus time, efficiency, time to a common relMSE); plot-convergence.py draws
# convergence.png. Then one `penumbra render --stats` per bdpt configuration (TIME seconds, seed 1)
# writes stats-<config>.json (the integrator's own counters, e.g. hrr_connections_per_eye_vertex,
# light_vertex_bvh_build_seconds) and the image beside the results.
#
# Settings (environment variables):
#   TIME        seconds per run (60)                 RUNS       runs per configuration (3)
#   REF         seconds for the reference (600)      REF_CONFIG configuration of the reference
#               (bdpt/hrr=true:sobol when bdpt declares hrr, else sppm/radius=0.03:halton)
#   REFERENCE   an existing reference EXR to reuse instead (reference-variance.exr beside it is used)
#   CONFIGS     comma-separated converge configurations, integrator[/NAME=VALUE...][:sampler]
#               (default below; configurations naming a parameter the integrator does not declare
#               are skipped with a note)
#   RES         resolution (160x120)   SNAPSHOTS per run (7)   THREADS (all cores)
#   SCENE       scene file (scenes/gdg-caustic/scene.pbrt)
#   OUT         output folder (bench/results/gdg-caustic)
#   STATS_INTEGRATORS  integrators whose configurations get a stats render (bdpt; "bdpt path" adds path)
#   BUILD       1: build first with scripts/build.sh (default); 0: use build/bin/penumbra as it is
# The defaults take about 25 minutes on 2 cores; TIME=2 RUNS=1 REF=4 BUILD=0 is a smoke test.
# sppm runs with its default radius (two pixel footprints since issue 13; this study used 1 m): at 30 s it had the lower relMSE overall, while
# sppm/radius=0.03:halton (about a pixel's footprint on the floor) keeps the caustic sharp but noisier.
set -euo pipefail
cd "$(dirname "$0")/.."
TIME=${TIME:-60}
RUNS=${RUNS:-3}
REF=${REF:-600}
RES=${RES:-160x120}
SNAPSHOTS=${SNAPSHOTS:-7}
SCENE=${SCENE:-scenes/gdg-caustic/scene.pbrt}
OUT=${OUT:-bench/results/gdg-caustic}
BUILD=${BUILD:-1}
STATS_INTEGRATORS=${STATS_INTEGRATORS:-bdpt}
CONFIGS=${CONFIGS:-path:sobol,bdpt:sobol,bdpt/hrr=true:sobol,bdpt/hrr=true/probconnect=true:sobol,sppm:halton}
if [ "$BUILD" = 1 ]; then scripts/build.sh >&2; fi
bin=build/bin/penumbra
[ -x "$bin" ] || { echo "error: $bin does not exist; build first (BUILD=1)" >&2; exit 1; }
[ -f "$SCENE" ] || { echo "error: scene $SCENE does not exist" >&2; exit 1; }
threads=()
[ -n "${THREADS:-}" ] && threads=(--threads "$THREADS")

# The plugin listing: "integrator 'NAME': doc" followed by indented "TYPE NAME doc" lines.
plugins=$($bin plugins 2>/dev/null || true)
has_integrator() { grep -q "^integrator '$1'" <<<"$plugins"; }
has_param() {  # has_param INTEGRATOR PARAM
  awk -v want="integrator '$1'" -v p="$2" '
    /^[a-z]+ / { inside = index($0, want) == 1 }
    inside && $1 != "" && $2 == p { found = 1 }
    END { exit !found }' <<<"$plugins"
}
# usable CONFIG: the integrator exists and declares every NAME of CONFIG's /NAME=VALUE parts.
usable() {
  local head=${1%%:*} integ params p
  integ=${head%%/*}
  has_integrator "$integ" || { echo "skipping $1: no integrator '$integ'" >&2; return 1; }
  [ "$head" = "$integ" ] && return 0
  IFS=/ read -r -a params <<<"${head#*/}"
  for p in "${params[@]}"; do
    has_param "$integ" "${p%%=*}" || { echo "skipping $1: integrator '$integ' has no parameter '${p%%=*}'" >&2; return 1; }
  done
}

list=()
IFS=, read -r -a wanted <<<"$CONFIGS"
for c in "${wanted[@]}"; do usable "$c" && list+=("$c"); done
[ ${#list[@]} -gt 0 ] || { echo "error: none of the configurations $CONFIGS can run" >&2; exit 1; }
joined=$(IFS=,; echo "${list[*]}")

mkdir -p "$OUT"
reference=()
if [ -n "${REFERENCE:-}" ]; then
  reference=(--reference "$REFERENCE")
  echo "== $SCENE: $joined against $REFERENCE" >&2
else
  if [ -z "${REF_CONFIG:-}" ]; then
    if has_param bdpt hrr; then REF_CONFIG="bdpt/hrr=true:sobol"; else REF_CONFIG="sppm/radius=0.03:halton"; fi
  fi
  usable "$REF_CONFIG" || { echo "error: the reference configuration $REF_CONFIG cannot run" >&2; exit 1; }
  reference=(--make-reference "$REF" --reference-config "$REF_CONFIG")
  echo "== $SCENE: $joined (reference $REF_CONFIG, ${REF}s)" >&2
fi
$bin converge "$SCENE" --configs "$joined" "${reference[@]}" --time "$TIME" --runs "$RUNS" \
  --snapshots "$SNAPSHOTS" --res "$RES" ${threads[@]+"${threads[@]}"} -o "$OUT"
if /usr/bin/python3 -c "import matplotlib" 2>/dev/null; then
  /usr/bin/python3 scripts/plot-convergence.py "$OUT" "$(basename "$OUT"): equal time, ${TIME}s x ${RUNS}"
fi

# One render with statistics per bdpt configuration: integrator/NAME=VALUE...:sampler -> options.
for c in "${list[@]}"; do
  head=${c%%:*}
  integ=${head%%/*}
  grep -qw -- "$integ" <<<"${STATS_INTEGRATORS//,/ }" || continue
  args=(--integrator "$integ")
  [ "$c" != "$head" ] && args+=(--sampler "${c#*:}")
  if [ "$head" != "$integ" ]; then
    IFS=/ read -r -a params <<<"${head#*/}"
    for p in "${params[@]}"; do args+=(--param "$p"); done
  fi
  safe=$(sed 's#[/:=,]#_#g' <<<"$c")  # bdpt/hrr=true:sobol -> bdpt_hrr_true_sobol
  echo "== stats: $c" >&2
  $bin render "$SCENE" "${args[@]}" --time "$TIME" --seed 1 --res "$RES" ${threads[@]+"${threads[@]}"} -q \
    -o "$OUT/render-$safe.exr" --stats "$OUT/stats-$safe.json"
done

# A short table on stdout.
/usr/bin/python3 - "$OUT/summary.json" <<'EOF'
import json, sys
s = json.load(open(sys.argv[1]))
print("%-44s %8s %12s %12s %10s" % ("configuration", "spp", "final relMSE", "efficiency", "t(relMSE)"))
for name, d in s["configs"].items():
    last = d["points"][-1]
    t = s["time_to_reach"]["seconds"].get(name, -1)
    print("%-44s %8.0f %12.4g %12.4g %10s" % (name, last["spp"], d["final_relmse"], d["efficiency"],
                                              "%.3g s" % t if t >= 0 else "never"))
print("time to relMSE %.4g (the worst final relMSE); results in %s" % (s["time_to_reach"]["relmse"],
                                                                     sys.argv[1].rsplit("/", 1)[0]))
EOF
