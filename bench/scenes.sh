# Benchmark scenes of bench/integrators.sh and bench/make-references.sh (sourced by both).
# One line per scene: short name, scene file (relative to the repository), reference integrator.
# The reference integrator is path tracing, except where path tracing cannot sample some of the
# light: through the glass sphere a point light's caustic is a specular path ending on a delta light,
# which only light tracing (bdpt's t = 1 strategy) renders.
BENCH_SCENE_TABLE="
cornell-spheres-area   scenes/bench/cornell-spheres-area.pbrt   bdpt
cornell-spheres-point  scenes/bench/cornell-spheres-point.pbrt  bdpt
cornell-spheres-env    scenes/bench/cornell-spheres-env.pbrt    path
cornell-box            scenes/cornell-box/scene.pbrt            path
cornell-water          bench/scenes/cornell-water-diffuse.pbrt  path
"

bench_scene_names() { awk 'NF == 3 { print $1 }' <<<"$BENCH_SCENE_TABLE"; }
bench_scene_file() { awk -v n="$1" '$1 == n { print $2 }' <<<"$BENCH_SCENE_TABLE"; }
bench_scene_reference_integrator() { awk -v n="$1" '$1 == n { print $3 }' <<<"$BENCH_SCENE_TABLE"; }

# Extra render options per integrator: none, every integrator runs with its defaults (sppm's initial
# radius comes from the pixel footprint).
bench_integrator_params() {
  echo ""
}

# Checks a comma-separated scene list; prints the names one a line.
bench_check_scenes() {
  local list="$1" s
  for s in ${list//,/ }; do
    if [ -z "$(bench_scene_file "$s")" ]; then
      echo "unknown scene '$s'; the benchmark scenes are: $(bench_scene_names | tr '\n' ' ')" >&2
      return 1
    fi
    echo "$s"
  done
}
