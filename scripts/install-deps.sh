#!/usr/bin/env bash
# Installs the Debian 12 packages FourierFlare needs, only those that are missing, without questions.
# Works as root (or through sudo). Says what it installs.
#   scripts/install-deps.sh           everything: the main job, tests, benchmarks, Python, packaging, farm
#   scripts/install-deps.sh --main    only what building and running the fourierflare command needs
#   scripts/install-deps.sh --fuzz    everything, and clang for the fuzzers
set -euo pipefail

# What the main job needs (scripts/run-main.sh): the compiler, the build tools and the libraries the
# fourierflare command links.
# Debian 12's OpenImageIO CMake config names the tools of openimageio-tools (iconvert, ...) and
# fails without them; CMake's FindOpenGL needs libOpenGL (libopengl-dev) beside EGL.
packages=(
  g++ cmake ninja-build pkg-config python3
  libembree-dev libglm-dev libtbb-dev
  libopenimageio-dev openimageio-tools libopenexr-dev
  libepoxy-dev libegl-dev libopengl-dev
  libopenblas-dev libfftw3-dev zlib1g-dev libzstd-dev
  libcli11-dev nlohmann-json3-dev
)
# The rest, for the tests, the benchmarks, the Python module, the Debian package and the farm
# (scripts/run-tests.sh): all of it unless --main is given.
if [ "${1:-}" != "--main" ]; then
  packages+=(
    git clang-format libegl-mesa0 libgl1-mesa-dri
    libgtest-dev libgmock-dev libbenchmark-dev libyaml-cpp-dev
    pybind11-dev python3-dev python3-numpy python3-pytest python3-openimageio
    dpkg-dev slurmctld slurmd slurm-client munge
    godot3 xvfb xauth
  )
fi
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
