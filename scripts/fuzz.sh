#!/usr/bin/env bash
# Fuzzes Penumbra's input readers with libFuzzer (clang from Debian) under AddressSanitizer and
# UndefinedBehaviorSanitizer, SECONDS each (default 60), each from a corpus of the bundled files:
#   parser  the scene parser (tests/fuzz/parser_fuzzer.cpp; corpus: every bundled .pbrt)
#   ply     the PLY reader (ply_fuzzer.cpp; the bundled .ply files)
#   gltf    the glTF loader (gltf_fuzzer.cpp; the bundled .gltf, as text and as a .glb guess)
#   image   environment images: read_image and the sampling distribution (image_fuzzer.cpp; small
#           bundled .exr files)
# Prints libFuzzer's summary per target; exits non-zero if any target found a crash, leak, timeout,
# out-of-memory or sanitizer report (the reproducer is left in build/fuzz/TARGET/).
#   scripts/fuzz.sh [SECONDS] [TARGET...]      (default: every target)
set -euo pipefail
cd "$(dirname "$0")/.."
budget=${1:-60}
shift || true
targets=("$@")
[ ${#targets[@]} -gt 0 ] || targets=(parser ply gltf image)
cxx="$(command -v clang++-14 || command -v clang++)"
flags=(-std=c++20 -g -O1 -fsanitize=fuzzer,address,undefined -fno-sanitize-recover=undefined
       -Icore/include -Icore/src -Itests -DPENUMBRA_SOURCE_DIR="\"$PWD\"")
common=(core/src/util/error.cpp core/src/util/params.cpp core/src/util/input_file.cpp core/src/util/output_file.cpp)
# The parser converts spectra as it reads (parser/spectrum_params.cpp): the spectrum code and the
# tables CMake embeds from data/spectra, generated here the same way.
mkdir -p build/fuzz
cmake -DSPECTRA_DIR="$PWD/data/spectra" -DOUTPUT="$PWD/build/fuzz/spectrum_tables.cpp" -P cmake/EmbedSpectra.cmake
spectra=(core/src/parser/spectrum_params.cpp core/src/spectra/named_spectra.cpp core/src/spectra/spd_file.cpp
         core/src/spectra/spectrum.cpp build/fuzz/spectrum_tables.cpp)

build_target() {
  case "$1" in
    parser) "$cxx" "${flags[@]}" core/src/parser/tokenizer.cpp core/src/parser/param_list.cpp core/src/parser/parser.cpp \
              core/src/parser/entity_directives.cpp core/src/parser/transform_directives.cpp "${common[@]}" "${spectra[@]}" \
              tests/fuzz/parser_fuzzer.cpp -lfmt -o "$2" ;;
    ply) "$cxx" "${flags[@]}" core/src/parser/ply_reader.cpp "${common[@]}" tests/fuzz/ply_fuzzer.cpp -lfmt -o "$2" ;;
    gltf) "$cxx" "${flags[@]}" core/src/scene/gltf_loader.cpp "${common[@]}" tests/fuzz/gltf_fuzzer.cpp \
            -ltinygltf -lfmt -o "$2" ;;
    image) "$cxx" "${flags[@]}" $(pkg-config --cflags OpenImageIO OpenColorIO) core/src/image/image_io.cpp \
             core/src/image/image_codecs.cpp core/oiio/oiio_codecs.cpp \
             core/src/util/sampling.cpp "${common[@]}" tests/fuzz/image_fuzzer.cpp \
             $(pkg-config --libs OpenImageIO OpenColorIO) -lfmt -o "$2" ;;
    *) echo "fuzz.sh: unknown target '$1' (parser, ply, gltf, image)" >&2; exit 2 ;;
  esac
}

# Seeds are named after their path: many bundled files share a base name (scene.pbrt).
seed_corpus() {
  local dir="$2" f
  case "$1" in
    parser) for f in $(find scenes -name '*.pbrt'); do cp "$f" "$dir/${f//\//_}"; done ;;
    ply) for f in $(find scenes tests -name '*.ply' -size -200k); do cp "$f" "$dir/${f//\//_}"; done ;;
    gltf) for f in $(find scenes tests -name '*.gltf' -size -200k); do  # first byte 0: read as .gltf
            { printf '\0'; cat "$f"; } >"$dir/${f//\//_}"
          done ;;
    image) for f in $(find tests/data scenes -name '*.exr' -size -64k); do  # first byte 0: .exr
             { printf '\0'; cat "$f"; } >"$dir/${f//\//_}"
           done ;;
  esac
}

status=0
for t in "${targets[@]}"; do
  out="build/fuzz/$t"
  mkdir -p "$out/corpus"
  seed_corpus "$t" "$out/corpus"
  build_target "$t" "$out/fuzzer"
  echo "fuzz.sh: $t for ${budget} s ($(ls "$out/corpus" | wc -l) seed files)" >&2
  # In its own folder: the parser may Include files relative to its input, and there are none there.
  if ! (cd "$out" && ./fuzzer -max_total_time="$budget" -max_len=65536 -timeout=10 -rss_limit_mb=2048 \
          -print_final_stats=1 corpus >log.txt 2>&1); then
    status=1
    echo "fuzz.sh: $t FOUND A PROBLEM (build/fuzz/$t/log.txt):" >&2
  fi
  grep -E "^(stat::number_of_executed_units|stat::new_units_added|stat::peak_rss_mb)|ERROR|SUMMARY|Done" "$out/log.txt" | tail -n 8
done
exit $status
