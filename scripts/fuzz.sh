#!/usr/bin/env bash
# Builds a libFuzzer target with clang (libFuzzer + ASan + UBSan) and runs it (docs/reliability.md).
#   scripts/fuzz.sh TARGET [SECONDS]     (default 600; TARGET: lens_parser zmx dat lights_json
#                                          ghosts_json table_json cache_entry plate
#                                          aperture_mask; "list" lists them)
# Seeds: fuzz/seeds/<target>/ (lens_parser: also the bundled lenses and ../shared/data/lenses-p2p
# when present); dictionary fuzz/dict/<target>.dict. New corpus entries go to build-fuzz/corpus/<target>
# (not committed); crashes, hangs (> 10 s) and memory blow-ups (> 2 GB) to build-fuzz/<target>-*.
set -euo pipefail
cd "$(dirname "$0")/.."
targets=(lens_parser zmx dat lights_json ghosts_json table_json cache_entry plate aperture_mask)
target="${1:-}"
seconds="${2:-600}"
if [ "$target" = list ]; then printf '%s\n' "${targets[@]}"; exit 0; fi
[[ " ${targets[*]} " == *" $target "* ]] || { echo "fuzz: TARGET is one of: ${targets[*]}" >&2; exit 2; }
command -v clang++ >/dev/null || { echo "fuzz: clang++ is needed (scripts/install-deps.sh --fuzz)" >&2; exit 1; }
# Configured and built under a lock: several targets can be started at once, one per core.
mkdir -p build-fuzz
(
  flock 9
  [ -f build-fuzz/CMakeCache.txt ] ||
    CC=clang CXX=clang++ cmake -S . -B build-fuzz -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DFF_BUILD_FUZZERS=ON \
      -DFF_BUILD_TESTS=OFF -DFF_BUILD_BENCHMARKS=OFF -DFF_BUILD_PYTHON=OFF >/dev/null
  cmake --build build-fuzz --target "${target}_fuzzer"
) 9>build-fuzz/.lock
case "$target" in
  lens_parser) seeds=(fuzz/seeds/lens_parser lenses); [ -d ../shared/data/lenses-p2p ] && seeds+=(../shared/data/lenses-p2p); dict=lens ;;
  lights_json|ghosts_json|table_json) seeds=("fuzz/seeds/${target%_json}"); dict=json ;;
  cache_entry) seeds=(fuzz/seeds/cache); dict="" ;;
  dat) seeds=(fuzz/seeds/dat); dict="" ;;
  plate|aperture_mask) seeds=(fuzz/seeds/plate); dict=exr ;;
  *) seeds=("fuzz/seeds/$target"); dict="$target" ;;
esac
corpus="build-fuzz/corpus/$target"
mkdir -p "$corpus"
options=(-max_total_time="$seconds" -timeout=10 -rss_limit_mb=2048 -artifact_prefix="build-fuzz/$target-")
[ -n "$dict" ] && options+=(-dict="fuzz/dict/$dict.dict")
exec "build-fuzz/fuzz/${target}_fuzzer" "${options[@]}" "$corpus" "${seeds[@]}"
