#!/usr/bin/env bash
# Runs one libFuzzer target under ctest: replays the regression inputs, then fuzzes for SECONDS
# from a scratch copy of the seed corpus (libFuzzer adds what it finds to its first corpus folder;
# the checked-in one stays as it is). A finding is kept in the scratch folder and named on stderr.
# Usage: run_fuzz.sh TARGET SEED_CORPUS REGRESSIONS SECONDS
set -euo pipefail
target=$1 seeds=$2 regressions=$3 seconds=$4
scratch=$(mktemp -d)
trap 'rm -rf "$scratch"' EXIT
export ASAN_OPTIONS=detect_leaks=1:allocator_may_return_null=1
export UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
if compgen -G "$regressions/*" >/dev/null; then
  "$target" -runs=0 -timeout=20 -rss_limit_mb=4096 -malloc_limit_mb=2560 "$regressions"/*
fi
mkdir -p "$scratch/corpus" "$scratch/findings"
cp -r "$seeds"/. "$scratch/corpus/"
cd "$scratch/findings"
if ! "$target" -max_total_time="$seconds" -timeout=20 -rss_limit_mb=4096 -malloc_limit_mb=2560 -max_len=65536 -print_final_stats=1 \
     "$scratch/corpus" 2>"$scratch/log"; then
  tail -n 60 "$scratch/log" >&2
  for f in "$scratch/findings"/*; do [ -e "$f" ] && echo "finding: $(basename "$f") ($(wc -c <"$f") bytes, base64 below; add it to $regressions/)" >&2 && base64 -w0 "$f" >&2 && echo >&2; done
  exit 1
fi
grep -E "stat::number_of_executed_units|cov:" "$scratch/log" | tail -n 2
