#!/usr/bin/env bash
# Installs the Debian 12 packages FourierFlare needs, only those that are missing, without questions.
# Works as root (or through sudo). Says what it installs.
set -euo pipefail

packages=(
  g++ cmake ninja-build pkg-config git clang-format python3
  libembree-dev libglm-dev libtbb-dev
  libopenimageio-dev openimageio-tools libopenexr-dev
  libepoxy-dev libegl-dev libegl-mesa0 libgl1-mesa-dri
  libopenblas-dev libfftw3-dev zlib1g-dev libzstd-dev
  libcli11-dev nlohmann-json3-dev
  libgtest-dev libgmock-dev libbenchmark-dev libyaml-cpp-dev
  pybind11-dev python3-dev python3-numpy python3-pytest python3-openimageio
  dpkg-dev slurmctld slurmd slurm-client munge
)
# Extra packages for the fuzzers (scripts/fuzz.sh): pass --fuzz.
if [ "${1:-}" = "--fuzz" ]; then packages+=(clang libclang-rt-14-dev); fi

missing=()
for p in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then missing+=("$p"); fi
done
if [ ${#missing[@]} -eq 0 ]; then
  echo "install-deps: all ${#packages[@]} required packages are installed"
  exit 0
fi

echo "install-deps: installing ${#missing[@]} missing package(s): ${missing[*]}"
sudo=""
if [ "$(id -u)" -ne 0 ]; then
  command -v sudo >/dev/null || { echo "install-deps: not root and no sudo; install these as root: ${missing[*]}" >&2; exit 1; }
  sudo="sudo"
fi
export DEBIAN_FRONTEND=noninteractive
$sudo apt-get update -qq
$sudo apt-get install -y -qq --no-install-recommends "${missing[@]}"
echo "install-deps: done"
