#!/usr/bin/env bash
# rsibr export blender against Blender itself: a synthetic run (minimal-grey, poses from the truth)
# exported and rendered in background Blender with Cycles. Checks that each view's camera puts the
# CG balls on the photo's balls (centre and radius of Cycles' coverage against the extract step's
# circles), and that the grey ball Cycles renders, extracted like the photo's, agrees with rsibr's
# computed grey map within Cycles' noise (two seeds) plus the run's own captured-vs-computed
# figure. Then the verb's contract: one-line errors, no partial output, --no-blend.
# Exit 77 (ctest: skipped) without Blender.
# Usage: blender_export_test.sh /path/to/rsibr
set -u
rsibr=$1
. "$(dirname "$0")/contract_lib.sh"
if ! command -v blender >/dev/null; then
  echo "SKIPPED: Blender is not installed (Debian's blender package; scripts/install-deps.sh installs it)"
  exit 77
fi

spec="$(dirname "$0")/../../datasets-synthetic/minimal-grey.yaml"
"$rsibr" synth "$spec" --out "$work/syn" -q
fres='{type: conductor, eta: [2.9, 2.9, 2.6], k: [3.4, 3.4, 3.2]}'
"$rsibr" process "$work/syn/photos" --out "$work/run" --poses "$work/syn/truth/truth.yaml" --chrome-fresnel "$fres" \
  --map-size 32 --turntable 1 --size 64x48 -q >/dev/null 2>"$work/process.err"
check "the run finished" test -s "$work/run/maps/computed-grey.exr"

"$rsibr" export blender "$work/run" --out "$work/bl" --json "$work/export.json" -q
check "export writes the .blend and what it refers to" bash -c "cd '$work/bl' && test -s scene.blend && test -s world.exr \
  && test -s photo_0001.exr && test -s photo_0003.exr && test -s fresnel-chrome.exr && test -s scene.json \
  && test -s build_blender_scene.py && ! ls -A | grep -q log"
check "export: three cameras and two balls in the summary" python3 -c "
import json; j = json.load(open('$work/export.json')); assert j['cameras'] == 3 and j['balls'] == 2, j"

# Renders frame F (view F-1) at SAMPLES with SEED into FILE; extra arguments pass through.
render() {
  local frame=$1 samples=$2 seed=$3 file=$4; shift 4
  blender -b "$work/bl/scene.blend" --python-exit-code 3 --python "$work/bl/build_blender_scene.py" -- \
    --render "$frame" --samples "$samples" --seed "$seed" --image "$file" "$@" >>"$work/blender.log" 2>&1
}

# 1. The balls sit on the photo's balls: Cycles' coverage of each ball alone, its centroid and
# equivalent radius, against the circle the extract step found in that view's photo.
mkdir -p "$work/alpha"
ok=1
for frame in 1 2 3; do
  for ball in chrome grey; do
    render "$frame" 4 0 "$work/alpha/$frame-$ball.exr" --alpha-of "$ball" || ok=0
  done
done
check "Cycles renders each ball alone" test "$ok" = 1
cat >"$work/circles.py" <<'PY'
import bpy, json, sys, numpy as np
work = sys.argv[sys.argv.index("--") + 1]
found = json.load(open(work + "/run/steps/extract.json"))["summary"]["views"]
worst = 0.0
for frame, view in enumerate(found, 1):
    for ball in view["balls"]:
        image = bpy.data.images.load("%s/alpha/%d-%s.exr" % (work, frame, ball["ball"]))
        w, h = image.size
        alpha = np.array(image.pixels[:]).reshape(h, w, 4)[::-1, :, 3]  # rows top first
        ys, xs = np.mgrid[0:h, 0:w]
        area = alpha.sum()
        cx, cy = (alpha * xs).sum() / area, (alpha * ys).sum() / area
        r = np.sqrt(area / np.pi)
        dc = np.hypot(cx - ball["centre_px"][0], cy - ball["centre_px"][1])
        dr = abs(r - ball["radius_px"])
        print("%s %s: centre off by %.3f px, radius by %.3f px (of %.1f)" % (view["name"], ball["ball"], dc, dr, r))
        worst = max(worst, dc, dr)
print("WORST %.4f" % worst)
PY
blender -b --python "$work/circles.py" -- "$work" >"$work/circles.log" 2>&1
grep " px" "$work/circles.log"
check "each CG ball lies on the photo's ball (centre and radius within 0.5 px)" python3 -c "
import re; w = [float(m) for m in re.findall(r'WORST ([0-9.]+)', open('$work/circles.log').read())]
assert w and w[0] < 0.5, w"

# 2. The grey ball Cycles renders under the exported world, extracted as the photos were, against
# rsibr's computed grey map: two seeds give Cycles' noise.
ok=1
for seed in 1 2; do
  mkdir -p "$work/cycles$seed"
  for frame in 1 2 3; do
    render "$frame" 64 "$seed" "$work/cycles$seed/view0$((frame - 1)).exr" || ok=0
  done
  "$rsibr" extract --photoset "$work/syn/photos" --merged "$work/cycles$seed" --lens "$work/run/lens.cameramodel" \
    --poses "$work/run/poses.yaml" --out "$work/x$seed" --size 32 --no-occluder-light --no-recover -q || ok=0
  "$rsibr" compare "$work/x$seed/captured-grey.exr" "$work/run/maps/computed-grey.exr" --json "$work/c$seed.json" -q || ok=0
done
check "Cycles renders every view and the renders extract" test "$ok" = 1
"$rsibr" compare "$work/x1/captured-grey.exr" "$work/x2/captured-grey.exr" --json "$work/noise.json" -q
check "Cycles' grey ball = the computed grey map within Cycles' noise + the run's captured-vs-computed figure" \
  python3 -c "
import json, math
def before(f): return json.load(open(f))['overall']['before']
noise = before('$work/noise.json')['relative_rms'] / math.sqrt(2)  # one render's
run = json.load(open('$work/run/steps/compare.json'))['summary']['balls'][0]['overall']['before']['relative_rms']
for s in (1, 2):
    b = before('$work/c%d.json' % s)
    ratio = [a / c for a, c in zip(b['mean_a'], b['mean_b'])]
    print('seed %d: relative RMS %.4f (noise %.4f, run %.4f), Cycles / computed means %s'
          % (s, b['relative_rms'], noise, run, ' '.join('%.4f' % r for r in ratio)))
    assert b['relative_rms'] < noise + run, (b['relative_rms'], noise, run)
    assert all(abs(r - 1) < 0.02 for r in ratio), ratio"

# 3. A map set as a scene: Cycles renders each view's sphere map (Lambert, three views, one of them
# oblique) within its own noise of rsibr's bake.
module="$(dirname "$rsibr")/python"
"$rsibr" pattern sun-sky "$work/sun.exr" --to latlong --size 128 >/dev/null
printf '0 0 1\n1 0 0\n0.3 0.8 0.2\n' >"$work/views.txt"
printf '{type: lambert, albedo: [0.8, 0.6, 0.4]}\n' >"$work/lambert.yaml"
"$rsibr" bake --env "$work/sun.exr" --brdf "$work/lambert.yaml" --views "$work/views.txt" --res 32 --method reference \
  "$work/lambert.exr" -q
"$rsibr" export blender --maps "$work/lambert.exr" --env "$work/sun.exr" --out "$work/ms" -q
ok=1
for seed in 1 2; do
  for frame in 1 2 3; do
    blender -b "$work/ms/scene.blend" --python-exit-code 3 --python "$work/ms/build_blender_scene.py" -- --render "$frame" \
      --samples 256 --seed "$seed" --image "$work/ms/s$seed-$frame.exr" >>"$work/blender.log" 2>&1 || ok=0
  done
done
check "Cycles renders every view of the exported map set" test "$ok" = 1
if [ -d "$module" ]; then
  cat >"$work/maps.py" <<'PY'
import bpy, sys, numpy as np
work, module = sys.argv[sys.argv.index("--") + 1:]
sys.path.insert(0, module)
import rsibr
maps = rsibr.read_map_set(work + "/lambert.exr")
def load(p):
    image = bpy.data.images.load(p); w, h = image.size
    return np.array(image.pixels[:], dtype=np.float64).reshape(h, w, 4)[::-1, :, :3]
for v in range(len(maps)):
    a = np.asarray(maps[v].rgb, dtype=np.float64)
    c1, c2 = (load("%s/ms/s%d-%d.exr" % (work, s, v + 1)) for s in (1, 2))
    n = a.shape[0]; ys, xs = np.mgrid[0:n, 0:n]
    inside = (2 * (xs + 0.5) / n - 1) ** 2 + (1 - 2 * (ys + 0.5) / n) ** 2 < 0.98 ** 2
    c = (c1 + c2) / 2
    bias = (c - a)[inside].sum() / a[inside].sum()
    rel = np.sqrt(((c - a)[inside] ** 2).sum() / (a[inside] ** 2).sum())
    noise = np.sqrt(((c1 - c2)[inside] ** 2 / 4).sum() / (a[inside] ** 2).sum())
    print("view %d: bias %+.4f relative RMS %.4f noise %.4f" % (v, bias, rel, noise))
    print("CHECK %d" % (abs(bias) < 0.003 + 4 * noise / np.sqrt(inside.sum()) and rel < np.hypot(noise, 0.003) * 1.2))
PY
  PATH=/usr/bin:$PATH blender -b --factory-startup --python "$work/maps.py" -- "$work" "$module" >"$work/maps.log" 2>&1
  grep "^view" "$work/maps.log"
  check "Cycles' render of each exported view = rsibr's map within its noise" \
    bash -c "[ \"\$(grep -c '^CHECK 1' '$work/maps.log')\" = 3 ]"
else
  echo "skipped the map-set comparison: the Python module is not built ($module)"
fi
expect_error "export: --maps without --env" "needs --env" export blender --maps "$work/lambert.exr" --out "$work/e6"
expect_error "export: a run and --maps" "not both" export blender "$work/run" --maps "$work/lambert.exr" \
  --env "$work/sun.exr" --out "$work/e7"
printf '{type: phong, albedo: [0.5, 0.5, 0.5], exponent: 20}\n' >"$work/phong.yaml"
"$rsibr" bake --env "$work/sun.exr" --brdf "$work/phong.yaml" --views "$work/views.txt" --res 8 "$work/phong.exr" -q
expect_error "export: a material Cycles has no counterpart for" "no Cycles counterpart" export blender \
  --maps "$work/phong.exr" --env "$work/sun.exr" --out "$work/e8" --no-blend

# 4. The contract.
expect_error "export: not a run" "steps/extract.json" export blender "$work/syn" --out "$work/e1"
check "export: nothing left after an error" bash -c "! ls -A '$work' | grep -q '^\.\?e1'"
expect_error "export: Blender missing" "nonexistent-blender" export blender "$work/run" --out "$work/e2" \
  --blender "$work/nonexistent-blender"
check "export: nothing left when Blender is missing" bash -c "! ls -A '$work' | grep -q '^\.\?e2'"
printf 'import sys\nsys.exit(5)\n' >"$work/fake.py"
printf '#!/bin/sh\nexit 9\n' >"$work/failing-blender"
chmod +x "$work/failing-blender"
expect_error "export: Blender fails" "Blender failed (exit 9)" export blender "$work/run" --out "$work/e3" \
  --blender "$work/failing-blender"
check "export: nothing left when Blender fails" bash -c "! ls -A '$work' | grep -q '^\.\?e3'"
cp -r "$work/run" "$work/broken"
python3 -c "
import json; f = '$work/broken/steps/extract.json'; j = json.load(open(f)); j['summary']['rig'] = [[1, 2, 3]]
json.dump(j, open(f, 'w'))"
expect_error "export: a record of the wrong shape is named" "broken/steps/extract.json" export blender "$work/broken" \
  --out "$work/e4" --no-blend
cp -r "$work/run" "$work/noballs"
echo '{}' > "$work/noballs/balls.json"
expect_error "export: a broken balls file is named" "noballs/balls.json" export blender "$work/noballs" \
  --out "$work/e6" --no-blend
cp -r "$work/run" "$work/noprobe"
rm "$work/noprobe/probe.exr"
expect_error "export: a run without its probe" "probe.exr: missing" export blender "$work/noprobe" --out "$work/e5" --no-blend
check "export: nothing left after those" bash -c "! ls -A '$work' | grep -q '^\.\?e[456]'"
"$rsibr" export blender "$work/run" --out "$work/nb" --no-blend -q
check "export --no-blend: the scene and script, no .blend" bash -c "test -s '$work/nb/scene.json' && test ! -e '$work/nb/scene.blend'"
check "export --help" bash -c "'$rsibr' export blender --help | grep -q Usage"
finish blender_export
