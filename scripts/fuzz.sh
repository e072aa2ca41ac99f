#!/usr/bin/env bash
# Builds a libFuzzer target with clang (libFuzzer + ASan + UBSan) and runs it (docs/reliability.md).
#   scripts/fuzz.sh TARGET [SECONDS]     (default 600; TARGET: lens_parser zmx dat lights_json
#                                          ghosts_json table_json cache_entry plate
#                                          aperture_mask; "list" lists them, "build" builds them all)
# Seeds: fuzz/seeds/<target>/ (lens_parser: also the bundled lenses and ../shared/data/lenses-p2p
# when present); a dictionary from fuzz/dict/ where the format has keywords. New corpus entries go to build-fuzz/corpus/<target>
# (not committed); crashes, hangs (> 10 s) and memory blow-ups (> 2 GB) to build-fuzz/<target>-*.
set -euo pipefail
cd "$(dirname "$0")/.."
targets=(lens_parser zmx dat lights_json ghosts_json table_json cache_entry plate aperture_mask)
target="${1:-}"
seconds="${2:-600}"
if [ "$target" = list ]; then printf '%s\n' "${targets[@]}"; exit 0; fi
[[ " ${targets[*]} build " == *" $target "* ]] || { echo "fuzz: TARGET is one of: ${targets[*]} (or build)" >&2; exit 2; }
command -v clang++ >/dev/null || { echo "fuzz: clang++ is needed (scripts/install-deps.sh --fuzz)" >&2; exit 1; }
# Configured and built under a lock: several targets can be started at once, one per core.
mkdir -p build-fuzz
(
  flock 9
  [ -f build-fuzz/CMakeCache.txt ] ||
    CC=clang CXX=clang++ cmake -S . -B build-fuzz -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DFF_BUILD_FUZZERS=ON \
      -DFF_BUILD_TESTS=OFF -DFF_BUILD_BENCHMARKS=OFF -DFF_BUILD_PYTHON=OFF >/dev/null
  if [ "$target" = build ]; then cmake --build build-fuzz --target "${targets[@]/%/_fuzzer}"; else cmake --build build-fuzz --target "${target}_fuzzer"; fi
) 9>build-fuzz/.lock
[ "$target" = build ] && exit 0
case "$target" in
  lens_parser) seeds=(fuzz/seeds/lens_parser lenses); [ -d ../shared/data/lenses-p2p ] && seeds+=(../shared/data/lenses-p2p); dict=lens ;;
  lights_json|ghosts_json|table_json) seeds=("fuzz/seeds/${target%_json}"); dict=json ;;
  cache_entry) seeds=(fuzz/seeds/cache); dict="" ;;
  dat) seeds=(fuzz/seeds/dat); dict="" ;;
  plate|aperture_mask) seeds=(fuzz/seeds/plate); dict=exr ;;
  *) seeds=("fuzz/seeds/$target"); dict="$target" ;;
esac
# FUZZ_CORPUS and FUZZ_ARTIFACTS put new inputs and findings elsewhere (scripts/fuzz-ci.sh).
corpus="${FUZZ_CORPUS:-build-fuzz/corpus/$target}"
artifacts="${FUZZ_ARTIFACTS:-build-fuzz}"
mkdir -p "$corpus" "$artifacts"
options=(-max_total_time="$seconds" -timeout=10 -rss_limit_mb=2048 -artifact_prefix="$artifacts/$target-")
[ -n "$dict" ] && options+=(-dict="fuzz/dict/$dict.dict")
export LSAN_OPTIONS="suppressions=$PWD/fuzz/lsan.supp${LSAN_OPTIONS:+:$LSAN_OPTIONS}"
# The image targets reach the image library, which crashes, hangs or exhausts memory on some damaged
# files (the CLI reads plates in a guarded process for that reason): go on past such findings and
# triage them afterwards (scripts/fuzz-triage.py: ours, or the library's and contained by the guard).
case "$target" in
  plate|aperture_mask) options+=(-fork=1 -ignore_crashes=1 -ignore_ooms=1 -ignore_timeouts=1) ;;
esac
exec "build-fuzz/fuzz/${target}_fuzzer" "${options[@]}" "$corpus" "${seeds[@]}"
