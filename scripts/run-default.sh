#!/usr/bin/env bash
# The main job on a built-in default, on a fresh Debian 12 machine as root: installs what rsibr
# needs, builds it, fetches CC0 data (a Poly Haven sky and the bunny via @pmndrs/assets) and runs
# the pipeline stages that exist so far: inspect the sky, convert it to every layout with PNG
# previews; bake a copper map set under it (12 views), blend a novel view, render the bunny with the
# maps (the runtime) and with the Embree reference path tracer, side by side; compare the FIS bake
# with an MIS bake of the same maps; synthesize a minimal ball-rig capture with its ground truth
# and merge its exposure brackets into radiance. Then the main job: synthesize the on-set dataset
# (datasets-synthetic/onset-outdoor.yaml: a chrome and a grey ball under the CC0 sky, 6 handheld
# views, a distorted lens, chessboards) and run `rsibr process` on it, ending with the path of its
# HTML report. Without the CC0 data (no network), only the main job runs, on minimal-grey.yaml.
# Outputs go to out/default/ (or the folder given as $1).
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."
out=${1:-out/default}

bash scripts/install-deps.sh
cmake --preset release >/dev/null
# Only the command the job runs (the tests, benchmarks and Python module are scripts/test.sh's).
cmake --build --preset release -j "$(nproc)" --target rsibr
have_assets=1
bash scripts/fetch-assets.sh || have_assets=0
rsibr=build/release/rsibr
env=cache/assets/hdri/sky.exr
mesh=cache/assets/models/bunny.glb

mkdir -p "$out"
if [ "$have_assets" = 1 ]; then
"$rsibr" info "$env" --json "$out/sky-info.json"
for layout in cube octahedral sphere latlong; do
  # --sanitize: the CC0 maps are DWAB-compressed and ring to negative values around the sun.
  "$rsibr" convert "$env" "$out/sky-$layout.exr" --to "$layout" --sanitize --preview "$out/sky-$layout.png" \
    --json "$out/sky-$layout.json"
done
"$rsibr" info "$out/sky-octahedral.exr"

# Computed maps: copper (GGX 0.2, conductor Fresnel) under the sky, the icosahedron's 12 views.
printf '{type: ggx, roughness: 0.2, fresnel: {type: conductor, eta: [0.2, 0.92, 1.1], k: [3.9, 2.45, 2.14]}}\n' \
  > "$out/copper.yaml"
"$rsibr" bake --env "$env" --brdf "$out/copper.yaml" --views icosa --res 128 --method fis --samples 32 \
  --sanitize --json "$out/copper-maps.json" "$out/copper-maps.exr"
"$rsibr" blend "$out/copper-maps.exr" "$out/copper-novel.exr" --view 0.2 0.3 0.9 --preview "$out/copper-novel.png"
# The bunny rendered with the maps (per-pixel mode) and by the reference path tracer without
# shadows (the maps' contract), same camera.
"$rsibr" render --maps "$out/copper-maps.exr" --mesh "$mesh" --size 640x360 --json "$out/bunny-render.json" \
  "$out/bunny-render.png"
"$rsibr" reference --mesh "$mesh" --env "$env" --brdf "$out/copper.yaml" --size 640x360 --spp 16 --no-shadows \
  --background black --sanitize --preview "$out/bunny-reference.png" --json "$out/bunny-reference.json" \
  "$out/bunny-reference.exr"
# Two integrators compared (metrics, fitted exposure/white balance, heat maps).
"$rsibr" bake --env "$env" --brdf "$out/copper.yaml" --views icosa --res 128 --method mis --samples 64 \
  --sanitize -q "$out/copper-maps-mis.exr"
rm -rf "$out/copper-compare"
"$rsibr" compare "$out/copper-maps.exr" "$out/copper-maps-mis.exr" --out "$out/copper-compare" \
  --json "$out/copper-compare.json"
# A synthetic capture (chrome ball, pinhole, 3 views, brackets, chessboards) and its HDR merge.
rm -rf "$out/synth-minimal"
"$rsibr" synth datasets-synthetic/minimal.yaml --out "$out/synth-minimal" --json "$out/synth-minimal.json"
"$rsibr" hdr "$out/synth-minimal/photos" --out "$out/synth-minimal/hdr" --json "$out/synth-minimal-hdr.json"
fi

# The main job: photos of a chrome and a grey ball -> rsibr process -> report.html. The orientations
# are solved from the chrome ball's reflections (features on cube faces of the reflected world, so
# the on-set views ~60 degrees apart share features). The featureless minimal-grey sky (no CC0 data)
# gives too few features: there, and only there, the synthetic truth's poses are used instead, and
# the report says so. Steps already done are skipped on the second call.
if [ "$have_assets" = 1 ]; then spec=datasets-synthetic/onset-outdoor.yaml mesh=(--mesh "$mesh"); else
  spec=datasets-synthetic/minimal-grey.yaml mesh=(); fi
rm -rf "$out/onset"
"$rsibr" synth "$spec" --out "$out/onset" --json "$out/onset-synth.json"
chrome='{type: conductor, eta: [2.9, 2.9, 2.6], k: [3.4, 3.4, 3.2]}'  # the synthetic chrome ball's
process=("$rsibr" process "$out/onset/photos" --out "$out/onset/process" --chrome-fresnel "$chrome" "${mesh[@]}"
  --json "$out/onset-process.json")
if [ "$have_assets" = 1 ]; then
  report=$("${process[@]}")
elif ! report=$("${process[@]}"); then
  echo "run-default: the orientation solve failed (above: the minimal sky is featureless); using the synthetic truth's poses" >&2
  report=$("${process[@]}" --poses "$out/onset/truth/truth.yaml")
fi
# The run as a Blender scene (world, cameras on their poses, the balls), with frame 1 rendered by
# Cycles over its photo; skipped where Blender is not installed.
if command -v blender >/dev/null; then
  "$rsibr" export blender "$out/onset/process" --out "$out/onset/blender" --preview 128 -q
  echo "run-default: Blender scene: $out/onset/blender/scene.blend (Cycles preview: preview.png)"
fi
echo "run-default: results in $out/ (EXR, PNG previews, JSON summaries)"
echo "run-default: report: $report"
