#!/usr/bin/env bash
# Quick start, second command (and what CI runs): install what is missing, then
#   stage 0: the C++ sources formatted as .clang-format says (scripts/check-format.sh),
#            docs/layering.md what the includes give (scripts/layering.py --check), no function in
#            src/ over 120 lines (scripts/function-length.py), and the fuzz targets built with
#            clang, which refuses some code gcc takes (a minute, not forty late);
#   stage 1: Release build, whole test suite through CTest;
#   stage 2: AddressSanitizer + UndefinedBehaviorSanitizer build, the fast tier again (every test
#            labelled *-fast: the slow tier repeats the fast one's code paths at larger sizes, and
#            under the sanitizers it took 13 of CI's minutes);
#   stage 3: fuzzing, the slow tier of the parsers: every libFuzzer target (clang) for 60 s from its
#            seeds, findings triaged (scripts/fuzz-ci.sh, docs/reliability.md).
# Exits non-zero if any stage fails.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install-deps.sh --fuzz
jobs="$(nproc 2>/dev/null || echo 2)"

echo "== stage 0: formatting, layering, function length and clang's build of the fuzz targets (a minute; fails early)"
scripts/check-format.sh
python3 scripts/layering.py --check
python3 scripts/function-length.py
scripts/fuzz.sh build >/dev/null

echo "== stage 1: Release build and tests"
scripts/build.sh release
ctest --test-dir build/release --output-on-failure -j "$jobs"

echo "== stage 2: ASan + UBSan build and the fast tier"
scripts/build.sh asan
ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
  ctest --test-dir build/asan --output-on-failure -j "$jobs" -L fast

echo "== stage 3: fuzzing, 60 s a target"
scripts/fuzz-ci.sh 60
