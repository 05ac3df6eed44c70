#!/usr/bin/env bash
# Installs every Debian 12 package rsibr needs to build, test and benchmark.
# Idempotent: packages already present are left as they are. Run as root.
set -euo pipefail

packages=(
  # toolchain
  build-essential cmake ninja-build pkg-config git ca-certificates
  # core
  libeigen3-dev libtbb-dev libopenexr-dev libimath-dev libopencolorio-dev
  libopencv-dev
  libcli11-dev libyaml-cpp-dev nlohmann-json3-dev
  libssl-dev  # pipeline/step_record.cpp: SHA-256 of the files a step read and wrote
  libopenmpi-dev openmpi-bin  # cluster/: mpirun bakes and batches (Open MPI)
  # meshes (core/mesh.cpp)
  libtinyobjloader-dev libtinygltf-dev libdraco-dev
  # bake / capture / calib / hdr
  libqhull-dev
  libembree-dev libceres-dev libmrcal-dev libmrgingham-dev mrgingham mrcal libexiv2-dev
  libraw-dev libtiff-dev  # hdr/raw_image.cpp: RAW brackets (LibRaw); capture/: DNG written with libtiff
  libheif-dev  # formats/heif_image.cpp: HEIF/HEIC photos (phones' default), opened on first use
  liblensfun-dev libglib2.0-dev  # calib/lens/photo_optics.cpp: camera crop factors (lensfun database; its .pc needs glib)
  libsuitesparse-dev  # calib/lens/intrinsics.cpp: cholmod (mrcal's Jacobian for the intrinsics covariance)
  # viewer (runtime/viewer; optional at build time) and its CI test under Xvfb (Mesa llvmpipe)
  libglfw3-dev libimgui-dev libepoxy-dev xvfb xauth libgl1-mesa-dri
  # tests and benchmarks; clang's libFuzzer for the fuzz targets (fuzz/)
  libgtest-dev libgmock-dev libbenchmark-dev clang-14 libclang-rt-14-dev
  clang-format-14  # tests/style: the tree stays formatted with .clang-format
  blender  # rsibr export blender writes .blend files through it; Cycles referees the bakes (tests/blender)
  chromium  # the page viewer's test (tests/viewer/web_viewer_test.py): headless, WebGL2 on SwiftShader
  # real-data fetch (npm registry) and docs plots
  python3 python3-numpy python3-matplotlib python3-yaml
  # the Python module (python/) and its tests (tests/python)
  python3-dev pybind11-dev python3-pybind11 python3-pytest
)
# node and npm: some images ship a nodejs that bundles npm (and conflicts with
# Debian's npm package); only ask apt for them when they are absent.
command -v node >/dev/null || packages+=(nodejs)
command -v npm >/dev/null || packages+=(npm)

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done

if ((${#missing[@]})); then
  export DEBIAN_FRONTEND=noninteractive
  apt-get update
  apt-get install -y --no-install-recommends "${missing[@]}"
else
  echo "install-deps: all ${#packages[@]} packages already installed"
fi
