#!/usr/bin/env bash
# Fuzzes the scene parser with libFuzzer (clang from Debian) under AddressSanitizer and
# UndefinedBehaviorSanitizer for SECONDS (default 60), starting from a corpus of every bundled scene.
# Prints libFuzzer's summary; exits non-zero if the fuzzer found a crash, leak or sanitizer report.
set -euo pipefail
cd "$(dirname "$0")/.."
SECONDS_BUDGET=${1:-60}
out=build/fuzz
mkdir -p "$out/corpus"
find scenes -name '*.pbrt' -exec cp {} "$out/corpus/" \;
"$(command -v clang++-14 || command -v clang++)" -std=c++20 -g -O1 -fsanitize=fuzzer,address,undefined -fno-sanitize-recover=undefined \
  -Icore/include -Icore/src \
  core/src/parser/tokenizer.cpp core/src/parser/param_list.cpp core/src/parser/parser.cpp \
  core/src/parser/entity_directives.cpp core/src/parser/transform_directives.cpp \
  core/src/util/error.cpp core/src/util/params.cpp tests/fuzz/parser_fuzzer.cpp \
  -lfmt -o "$out/parser_fuzzer"
# The fuzzer's working directory holds nothing to include but the corpus itself.
cd "$out"
./parser_fuzzer -max_total_time="$SECONDS_BUDGET" -max_len=8192 -timeout=10 -rss_limit_mb=2048 \
  -print_final_stats=1 corpus 2>&1 | tail -n 25
