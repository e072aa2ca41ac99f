#!/usr/bin/env bash
# CI's fuzzing stage (docs/reliability.md): every fuzz target for SECONDS (default 60) from its seed
# corpus in the tree, as many at once as there are cores, new inputs and findings in a scratch folder;
# then every finding triaged (scripts/fuzz-triage.py). Fails on a finding in our code, or one in the
# image library that the CLI's guarded read does not contain (exit 2 within 10 s, nothing written).
#   scripts/fuzz-ci.sh [SECONDS]      (needs clang: scripts/install-deps.sh --fuzz; and build/release)
set -euo pipefail
cd "$(dirname "$0")/.."
seconds="${1:-60}"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
# A build that fails says why on stdout (the compiler's errors), not only on stderr.
scripts/fuzz.sh build >"$work/build.log" 2>&1 || { echo "fuzz-ci: the fuzz build failed:"; grep -E "error|Error" "$work/build.log" | head -40; exit 1; }
export work seconds
scripts/fuzz.sh list | xargs -P "$(nproc 2>/dev/null || echo 2)" -I{} bash -c '
  code=0
  FUZZ_CORPUS="$work/corpus/$1" FUZZ_ARTIFACTS="$work/findings" scripts/fuzz.sh "$1" "$seconds" >"$work/$1.log" 2>&1 || code=$?
  echo "fuzz-ci: $1: exit $code, $(grep -Eo "^#[0-9]+" "$work/$1.log" | tail -1 | tr -d "#") executions,$(grep -Eo "cov: [0-9]+" "$work/$1.log" | tail -1 | cut -c5-) edges"
  # A failure that left no finding (a build or start-up error) is reported here; findings are triaged below.
  if [ "$code" -ne 0 ] && ! compgen -G "$work/findings/$1-*" >/dev/null; then tail -20 "$work/$1.log"; echo "$1" >>"$work/failed"; fi
' _ {}
shopt -s nullglob
findings=("$work"/findings/*)
status=0
[ ! -s "$work/failed" ] || { echo "fuzz-ci: failed without a finding: $(tr '\n' ' ' <"$work/failed")"; status=1; }
if [ ${#findings[@]} -eq 0 ]; then echo "fuzz-ci: no findings"; exit "$status"; fi
python3 scripts/fuzz-triage.py "${findings[@]}" || status=1
exit "$status"
