#!/usr/bin/env bash
# Fails when a C++ file of the repository differs from what clang-format makes of it (.clang-format
# at the root), naming the files. Usage: check_format.sh CLANG_FORMAT SOURCE_DIR
set -euo pipefail
clang_format=$1
cd "$2"
if ! git rev-parse --is-inside-work-tree >/dev/null 2>&1; then
  echo "check_format: $2 is not a git checkout; nothing to check"
  exit 0
fi
# One clang-format for every file: each unformatted one is reported as "<file>:<line>:<col>: error".
out=$(git ls-files -z '*.cpp' '*.h' | xargs -0 "$clang_format" --style=file --dry-run --Werror 2>&1) || true
bad=$(printf '%s\n' "$out" | grep -oE '^[^: ]+\.(cpp|h):[0-9]+:[0-9]+: error' | cut -d: -f1 | sort -u || true)
if [ -n "$bad" ]; then
  echo "not formatted with .clang-format (run clang-format -i on them):" >&2
  printf '  %s\n' $bad >&2
  exit 1
fi
echo "check_format: every C++ file is formatted"
