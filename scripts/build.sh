#!/usr/bin/env bash
# Configures and builds one flavour of FourierFlare.
#   scripts/build.sh release    -> build/release   (Release; tests and benchmarks included)
#   scripts/build.sh asan       -> build/asan      (AddressSanitizer + UndefinedBehaviorSanitizer)
set -euo pipefail
cd "$(dirname "$0")/.."
flavour="${1:-release}"
jobs="$(nproc 2>/dev/null || echo 2)"
case "$flavour" in
  release) cmake -S . -B build/release -G Ninja -DCMAKE_BUILD_TYPE=Release -DFF_WERROR=ON ;;
  asan)    cmake -S . -B build/asan -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DFF_SANITIZE=ON \
                 -DFF_BUILD_BENCHMARKS=OFF -DFF_BUILD_PYTHON=OFF -DFF_WERROR=ON ;;
  *) echo "build.sh: unknown flavour '$flavour' (release or asan)" >&2; exit 2 ;;
esac
cmake --build "build/$flavour" -j "$jobs"
