#!/usr/bin/env bash
# Configures and builds one flavour of FourierFlare.
#   scripts/build.sh main       -> build/release   (Release; the fourierflare command and its man page only)
#   scripts/build.sh release    -> build/release   (Release; tests, benchmarks and the Python module included)
#   scripts/build.sh asan       -> build/asan      (AddressSanitizer + UndefinedBehaviorSanitizer)
set -euo pipefail
cd "$(dirname "$0")/.."
flavour="${1:-release}"
jobs="$(nproc 2>/dev/null || echo 2)"
targets=()
case "$flavour" in
  main)    # A folder configured already (by the release flavour) keeps its options: only fewer targets.
           parts=(-DFF_BUILD_TESTS=OFF -DFF_BUILD_BENCHMARKS=OFF -DFF_BUILD_PYTHON=OFF)
           [ -f build/release/CMakeCache.txt ] && parts=()
           cmake -S . -B build/release -G Ninja -DCMAKE_BUILD_TYPE=Release -DFF_WERROR=ON "${parts[@]}"
           targets=(--target fourierflare man_page)
           flavour=release ;;
  release) cmake -S . -B build/release -G Ninja -DCMAKE_BUILD_TYPE=Release -DFF_WERROR=ON \
                 -DFF_BUILD_TESTS=ON -DFF_BUILD_BENCHMARKS=ON -DFF_BUILD_PYTHON=ON ;;
  asan)    cmake -S . -B build/asan -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DFF_SANITIZE=ON \
                 -DFF_BUILD_BENCHMARKS=OFF -DFF_BUILD_PYTHON=OFF -DFF_WERROR=ON ;;
  *) echo "build.sh: unknown flavour '$flavour' (main, release or asan)" >&2; exit 2 ;;
esac
cmake --build "build/$flavour" -j "$jobs" "${targets[@]}"
