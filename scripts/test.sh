#!/usr/bin/env bash
# Builds if needed, then runs every test through CTest (unit, statistical and whole-render tests).
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/build.sh
ctest --test-dir build --output-on-failure -j"$(nproc)" "$@"
