#!/usr/bin/env bash
# The main job on a built-in default, on a fresh Debian 12 machine as root: installs what rsibr
# needs, builds it, fetches a CC0 environment (Poly Haven via @pmndrs/assets) and runs the
# pipeline stages that exist so far on it: inspect it, convert it to every layout with PNG
# previews, and inspect a result. Outputs go to out/default/ (or the folder given as $1).
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."
out=${1:-out/default}

bash scripts/install-deps.sh
cmake --preset release >/dev/null
cmake --build --preset release -j "$(nproc)"
bash scripts/fetch-assets.sh
rsibr=build/release/rsibr
env=cache/assets/hdri/sky.exr

mkdir -p "$out"
"$rsibr" info "$env" --json "$out/sky-info.json"
for layout in cube octahedral sphere latlong; do
  # --sanitize: the CC0 maps are DWAB-compressed and ring to negative values around the sun.
  "$rsibr" convert "$env" "$out/sky-$layout.exr" --to "$layout" --sanitize --preview "$out/sky-$layout.png" \
    --json "$out/sky-$layout.json"
done
"$rsibr" info "$out/sky-octahedral.exr"
echo "run-default: results in $out/ (EXR, PNG previews, JSON summaries)"
