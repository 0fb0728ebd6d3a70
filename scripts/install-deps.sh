#!/usr/bin/env bash
# Installs Penumbra's build and test dependencies from Debian 12's archive. Idempotent: packages that are
# already present are skipped, and apt-get runs only when something is missing.
set -euo pipefail

packages=(
  build-essential cmake ninja-build pkg-config
  libembree-dev libopenimageio-dev openimageio-tools python3-imath
  libopencolorio-dev libtinygltf-dev libglm-dev libtbb-dev
  libcli11-dev nlohmann-json3-dev libfmt-dev
  libgtest-dev libgmock-dev libbenchmark-dev
  python3-matplotlib python3-numpy
  git python3   # bench/integrators.sh: commit hash in its history, table and CSV (standard library only)
  clang-14 libclang-rt-14-dev
  chromium
  slurm-wlm munge   # tests/farm/slurm_preempt_test.sh: a real single-node cluster
)

missing=()
for p in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

if [ ${#missing[@]} -eq 0 ]; then
  echo "install-deps: all ${#packages[@]} packages present" >&2
  exit 0
fi

echo "install-deps: installing ${missing[*]}" >&2
SUDO=""
if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
