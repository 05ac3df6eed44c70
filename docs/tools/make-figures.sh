#!/usr/bin/env bash
# Regenerates docs/figures/*.png (the figures of docs/conventions.md) from rsibr_core's own
# direction <-> pixel mappings and view-set triangulation.
#
#   docs/tools/make-figures.sh [output folder]      (default: docs/figures)
#
# Uses the layout_figures target of the build tree $RSIBR_BUILD_DIR (default build/release) when
# that tree has it (top-level CMakeLists.txt: add_subdirectory(docs/tools)); otherwise builds
# rsibr_core there and compiles the tool directly against it.
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)
build=${RSIBR_BUILD_DIR:-$root/build/release}
out=${1:-$root/docs/figures}
jobs=${JOBS:-2}

if [[ ! -f $build/CMakeCache.txt ]]; then
  echo "make-figures: no configured build tree at $build (run: cmake --preset release)" >&2
  exit 1
fi

if cmake --build "$build" --target help 2>/dev/null | grep -q '\blayout_figures\b'; then
  cmake --build "$build" --target layout_figures -j "$jobs"
  exe=$build/docs/tools/layout_figures
else
  echo "make-figures: $build has no layout_figures target; compiling docs/tools/layout_figures.cpp directly" >&2
  cmake --build "$build" --target rsibr_core -j "$jobs"
  tmp=$(mktemp -d)
  trap 'rm -rf "$tmp"' EXIT
  exe=$tmp/layout_figures
  # shellcheck disable=SC2046
  g++ -std=c++20 -O2 -Wno-deprecated-enum-enum-conversion -I"$root" -I/usr/include/eigen3 \
    -isystem /usr/include/opencv4 $(pkg-config --cflags OpenEXR) \
    "$root/docs/tools/layout_figures.cpp" "$build/core/librsibr_core.a" -o "$exe" \
    $(pkg-config --libs OpenEXR OpenColorIO yaml-cpp) \
    -lopencv_core -lopencv_imgproc -lopencv_imgcodecs -ltbb -lqhull_r
fi
"$exe" "$out"
