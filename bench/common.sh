# Helpers shared by the scripts of bench/ (sourced).

# Short commit hash, "+dirty" when tracked files differ from it (the benchmark's own results and
# references under bench/results/ and bench/references/ do not count).
bench_commit() {
  local root="$1" hash
  hash=$(git -C "$root" rev-parse --short HEAD 2>/dev/null || echo unknown)
  if [ "$hash" != unknown ] && [ -n "$(git -C "$root" status --porcelain --untracked-files=no -- . \
      ':(exclude)bench/results' ':(exclude)bench/references' 2>/dev/null)" ]; then
    hash="$hash+dirty"
  fi
  echo "$hash"
}

bench_cpu_model() {
  local m
  m=$(awk -F': *' '/^model name/ { print $2; exit }' /proc/cpuinfo 2>/dev/null)
  [ -n "$m" ] || m=$(uname -m)
  echo "$m"
}

bench_loadavg() { cut -d' ' -f1 /proc/loadavg 2>/dev/null || echo ""; }

# The build's binaries; exits with a hint when they are missing.
bench_find_build() {
  local build="$1" b
  for b in penumbra penumbra-bench-image-errors penumbra-bench-render; do
    if [ ! -x "$build/bin/$b" ]; then
      echo "missing $build/bin/$b; build first: cmake -B build -G Ninja -DCMAKE_BUILD_TYPE=Release && cmake --build build -j2" >&2
      exit 1
    fi
  done
}

# Python with the interpreter the project's scripts use (Debian's, where python3-matplotlib lives).
bench_python() {
  if [ -x /usr/bin/python3 ]; then echo /usr/bin/python3; else echo python3; fi
}

# "native" when the build makes code for this processor only (configured with
# -DPENUMBRA_NATIVE_ARCH=ON, or -march=native in CMAKE_CXX_FLAGS), "x86-64" otherwise: figures from
# the two are not comparable (docs/benchmarks.md).
bench_build_arch() {
  if grep -qE '^PENUMBRA_NATIVE_ARCH:BOOL=ON$|^CMAKE_CXX_FLAGS:STRING=.*-march=native' "$1/CMakeCache.txt" 2>/dev/null; then
    echo native
  else
    echo x86-64
  fi
}

# Sets $work to the folder where a run keeps its files: KEEP (created) when given, otherwise a new
# temporary folder named after PREFIX that is removed when the script exits.
bench_work_dir() {
  local keep="$1" prefix="$2"
  if [ -n "$keep" ]; then
    work="$keep"
    mkdir -p "$work"
  else
    work=$(mktemp -d "${TMPDIR:-/tmp}/$prefix.XXXXXX")
    trap 'rm -rf "$work"' EXIT
  fi
}

# The set-up every per-(scene, integrator) benchmark script makes once its options are read: sets
# scene_list and integrator_list (one a word) from the comma-separated SCENES and INTEGRATORS, checks
# BUILD, and sets py, work (bench_work_dir KEEP PREFIX), date_iso, commit (of $root), cpu and arch.
bench_prepare() {
  local scenes="$1" integrators="$2" build="$3" keep="$4" prefix="$5"
  scene_list=$(bench_check_scenes "$scenes") || exit 1
  integrator_list=${integrators//,/ }
  bench_find_build "$build"
  py=$(bench_python)
  bench_work_dir "$keep" "$prefix"
  date_iso=$(date -Iseconds)
  commit=$(bench_commit "$root")
  cpu=$(bench_cpu_model)
  arch=$(bench_build_arch "$build")
}
