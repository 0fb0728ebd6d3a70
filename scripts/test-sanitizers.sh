#!/usr/bin/env bash
# Builds the whole project with AddressSanitizer and UndefinedBehaviorSanitizer (gcc, -O1) into
# build-asan/ and runs the test suite under them; any sanitizer report fails the test that caused it.
# Left out (and why): the time-budget tests (they measure wall-clock overrun, which instrumentation
# changes) and the farm test (the same programs run in the plain suite; its daemons are not ours).
#   scripts/test-sanitizers.sh [ctest options...]
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install-deps.sh
generator=()
command -v ninja >/dev/null 2>&1 && generator=(-G Ninja)
flags="-O1 -g -fno-omit-frame-pointer -fsanitize=address,undefined -fno-sanitize-recover=undefined"
if [ ! -f build-asan/CMakeCache.txt ]; then
  cmake -B build-asan "${generator[@]}" -DCMAKE_BUILD_TYPE=Debug \
    -DCMAKE_CXX_FLAGS="$flags" -DCMAKE_C_FLAGS="$flags" \
    -DCMAKE_EXE_LINKER_FLAGS="-fsanitize=address,undefined" -DCMAKE_SHARED_LINKER_FLAGS="-fsanitize=address,undefined"
fi
cmake --build build-asan -j"$(nproc)"
# Leaks in the libraries we link (TBB's worker threads, OpenImageIO's plugin cache) are theirs:
# listed in scripts/lsan-suppressions.txt; every other leak fails.
export ASAN_OPTIONS="detect_leaks=1:abort_on_error=1:strict_string_checks=1:detect_stack_use_after_return=0"
export LSAN_OPTIONS="suppressions=$PWD/scripts/lsan-suppressions.txt:print_suppressions=0"
export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1"
ctest --test-dir build-asan --output-on-failure -j"$(nproc)" -E "TimeBudget|Farm\." "$@"
