#!/usr/bin/env bash
# Builds the lens-parser fuzzer with clang (libFuzzer + ASan + UBSan) and runs it.
#   scripts/fuzz-lens-parser.sh [SECONDS]     (default 600)
# Seeds: fuzz/seeds, the bundled lenses, and ../shared/data/lenses-p2p when present. New corpus
# entries go to build-fuzz/corpus (not committed); crashes to build-fuzz/crash-*.
set -euo pipefail
cd "$(dirname "$0")/.."
seconds="${1:-600}"
command -v clang++ >/dev/null || { echo "fuzz: clang++ is needed (apt-get install clang libclang-rt-14-dev)"; exit 1; }
CC=clang CXX=clang++ cmake -S . -B build-fuzz -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DFF_BUILD_FUZZERS=ON -DFF_BUILD_TESTS=OFF -DFF_BUILD_BENCHMARKS=OFF >/dev/null
cmake --build build-fuzz --target lens_parser_fuzzer
mkdir -p build-fuzz/corpus
seeds=(fuzz/seeds lenses)
[ -d ../shared/data/lenses-p2p ] && seeds+=(../shared/data/lenses-p2p)
cd build-fuzz
exec ./fuzz/lens_parser_fuzzer -max_total_time="$seconds" -max_len=8192 -timeout=10 -rss_limit_mb=2048 \
  -artifact_prefix=./ corpus "${seeds[@]/#/../}"
