#!/usr/bin/env bash
# Fails (exit 1) naming every C++ file that clang-format (Debian 12's, 14) would change: the tree is
# kept formatted by .clang-format. Fix with: git ls-files '*.cpp' '*.h' | xargs clang-format -i
set -euo pipefail
cd "$(dirname "$0")/.."
bad=()
while IFS= read -r f; do
  clang-format --dry-run --Werror "$f" > /dev/null 2>&1 || bad+=("$f")
done < <(git ls-files '*.cpp' '*.h' '*.hpp')
if [ "${#bad[@]}" -gt 0 ]; then
  printf 'check-format: not formatted (clang-format -i fixes it): %s\n' "${bad[@]}" >&2
  exit 1
fi
echo "check-format: $(git ls-files '*.cpp' '*.h' '*.hpp' | wc -l) files formatted"
