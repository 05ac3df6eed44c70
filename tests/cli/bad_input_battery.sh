#!/usr/bin/env bash
# The bad-input battery: every verb given hostile files and options. For each refused case the
# contract is: no signal, no timeout, a non-zero exit, exactly one line on stderr naming the file or
# option at fault, no output left anywhere (the whole scratch tree is compared), and every input
# byte-identical. Cases that are valid but extreme (--sanitize, 1x1 maps, one view) must succeed
# with no NaN or Inf in any output.
# Usage: bad_input_battery.sh /path/to/rsibr /path/to/rsibr_bad_inputs
set -u
rsibr=$1
make_bad=$2
here=$(cd "$(dirname "$0")" && pwd)
. "$here/contract_lib.sh"
in="$work/in" out="$work/o"
mkdir -p "$in" "$out"

# ---- fixtures (inputs: never modified)
"$make_bad" "$in"
printf 'type: ggx\nroughness: 0.3\nfresnel: {type: schlick, f0: [0.9, 0.7, 0.4]}\n' >"$in/ggx.yaml"
printf 'type: lambert\nalbedo: [0.5, 0.5, 0.5]\n' >"$in/lambert.yaml"
printf '&c {type: clearcoat, coat: *c}\n' >"$in/cycle.yaml"
printf 'type: ggx\nroughness: 0.3\nfresnel: &f {type: schlick, f0: [*f, 1, 1]}\n' >"$in/fresnel-cycle.yaml"
{ echo "l0: &l0 [x, x]"; for i in $(seq 1 40); do echo "l$i: &l$i [*l$((i - 1)), *l$((i - 1))]"; done; } >"$in/bomb.yaml"
printf 'v 1 0 0\nv -1 0 0\nv 0 1 0\nv 0 -1 0\nv 0 0 1\nv 0 0 -1\nf 1 3 5\nf 3 2 5\nf 2 4 5\nf 4 1 5\nf 3 1 6\nf 2 3 6\nf 4 2 6\nf 1 4 6\n' >"$in/octa.obj"
printf 'v 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\n' >"$in/degenerate.obj"
printf 'v 0 0 0\nf 1 2 3\n' >"$in/bad-index.obj"
{ cat "$in/octa.obj"; printf 'v 0 0 0\nv 1e-30 0 0\nf 7 8 7\nf 1 1 2\n'; } >"$in/mixed.obj"
head -c 300 "$in/env-good.exr" >"$in/env-truncated.exr"
head -c 400 "$in/maps-good.exr" >"$in/maps-truncated.exr"
python3 - "$in" <<'PY'
import sys
d = sys.argv[1]
for name in ("env-good.exr", "maps-good.exr"):
    b = bytearray(open(f"{d}/{name}", "rb").read())
    for i in range(len(b) // 3, len(b), 97):  # flip bits all over the pixel data and offsets
        b[i] ^= 0x5A
    open(f"{d}/{name.replace('good', 'flipped')}", "wb").write(bytes(b))
PY
: >"$in/empty.exr"
printf 'plain text, not an image\n' >"$in/text.exr"
mkdir -p "$in/folder.exr"
mkfifo "$in/fifo.exr"
pinhole_lens "$in/lens.cameramodel"
printf "{ 'lensmodel': 'LENSMODEL_PINHOLE', 'intrinsics': [ 100, 100, 47.5 " >"$in/truncated.cameramodel"
# A bracketed shoot and its broken variants (photos).
python3 "$here/bracket_shoot.py" "$in/shoot"
"$rsibr" hdr "$in/shoot" --out "$in/shoot-hdr" -q --no-preview
variant() {  # variant NAME: a copy of the shoot, to break
  cp -r "$in/shoot" "$in/$1"
}
variant png-truncated; head -c 200 "$in/shoot/north/2.png" >"$in/png-truncated/north/2.png"
variant png-flipped; python3 -c "
import sys; p = '$in/png-flipped/north/2.png'; b = bytearray(open(p, 'rb').read())
for i in range(60, len(b), 13): b[i] ^= 0xFF
open(p, 'wb').write(bytes(b))"
variant zero-exposure; sed -i '0,/exposure_s: [0-9.e-]*/s//exposure_s: 0/' "$in/zero-exposure/photoset.yaml"
variant equal-exposures; sed -i 's/exposure_s: [0-9.e-]*/exposure_s: 0.01/' "$in/equal-exposures/photoset.yaml"
variant no-exposures; sed -i 's/, exposure_s: [0-9.e-]*//' "$in/no-exposures/photoset.yaml"
variant missing-photo; rm "$in/missing-photo/north/3.png"
variant resized; python3 - "$in/resized/north/4.png" <<'PY'
import struct, sys, zlib
raw = b"".join(b"\x00" + bytes(3 * 50) for _ in range(30))
ch = lambda t, d: struct.pack(">I", len(d)) + t + d + struct.pack(">I", zlib.crc32(t + d) & 0xffffffff)
open(sys.argv[1], "wb").write(b"\x89PNG\r\n\x1a\n" + ch(b"IHDR", struct.pack(">IIBBBBB", 50, 30, 8, 2, 0, 0, 0))
                              + ch(b"IDAT", zlib.compress(raw)) + ch(b"IEND", b""))
PY
variant unknown-key; sed -i '1a colour: red' "$in/unknown-key/photoset.yaml"
variant bomb-set; cat "$in/bomb.yaml" >>"$in/bomb-set/photoset.yaml"
if [ -s "$here/../../cache/assets/models/bunny.glb" ]; then
  head -c 5000 "$here/../../cache/assets/models/bunny.glb" >"$in/truncated.glb"
else
  printf 'glTF\x02\x00\x00\x00\xff\xff\x00\x00' >"$in/truncated.glb"
fi
cp "$in/shoot-hdr/north.exr" "$in/north-copy.exr"
cp "$here/../../datasets-synthetic/minimal.yaml" "$in/minimal.yaml"
find "$in" -type f -exec sha256sum {} + | sort >"$work/inputs.sha"

# Everything under $work but the harness's scratch files, one path a line.
tree() { (cd "$work" && find . -mindepth 1 ! -name out ! -name err ! -name before ! -name after ! -name inputs.sha ! -path './o/pr/*' | sort); }

# refused NAME NEEDLE ARGS...: the whole contract for a refused case.
refused() {
  local name=$1 needle=$2; shift 2
  tree >"$work/before"
  timeout 120 "$rsibr" "$@" >"$work/out" 2>"$work/err"
  local rc=$?
  tree >"$work/after"
  local lines; lines=$(wc -l <"$work/err")
  local why=""
  if [ "$rc" -eq 124 ]; then why="timed out"
  elif [ "$rc" -ge 128 ]; then why="killed by signal $((rc - 128))"
  elif [ "$rc" -eq 0 ]; then why="exit 0"
  elif [ "$lines" -ne 1 ]; then why="$lines lines on stderr"
  elif ! grep -q -- "$needle" "$work/err"; then why="the message does not name '$needle'"
  elif ! cmp -s "$work/before" "$work/after"; then why="left output: $(diff "$work/before" "$work/after" | grep '^>' | head -3 | tr '\n' ' ')"
  fi
  if [ -z "$why" ]; then pass=$((pass + 1)); else
    fail=$((fail + 1)); echo "FAILED: $name: $why"; head -3 "$work/err"
    # Start the next case clean.
    comm -13 "$work/before" "$work/after" | while read -r p; do rm -rf "${work:?}/$p"; done
  fi
}
# finite_output NAME FILE: FILE (an environment or a map set) holds no NaN or Inf.
finite_output() {
  check "$1: no NaN or Inf in $(basename "$2")" python3 -c "
import json, subprocess, sys
j = json.loads(subprocess.run(['$rsibr', 'info', '$2', '--json', '-'], capture_output=True, text=True, check=True).stdout)
bad = j.get('unusable_values', 0) if j.get('kind') == 'map set' else j['nan'] + j['inf'] + j['huge']
sys.exit(1 if bad else 0)"
}
# accepted NAME ARGS...: runs to success, no signal, no timeout.
accepted() {
  local name=$1; shift
  timeout 120 "$rsibr" "$@" >"$work/out" 2>"$work/err"
  local rc=$?
  if [ "$rc" -eq 0 ]; then pass=$((pass + 1)); else fail=$((fail + 1)); echo "FAILED: $name: exit $rc"; head -3 "$work/err"; fi
}

# ---- unreadable files, for every verb that reads that kind of file
for f in env-truncated env-flipped empty text folder fifo; do
  refused "info: $f" "$f.exr" info "$in/$f.exr"
  refused "convert: $f" "$f.exr" convert "$in/$f.exr" "$out/c.exr" --to cube --size 8
  refused "bake: environment $f" "$f.exr" bake --env "$in/$f.exr" --brdf "$in/ggx.yaml" --res 8 "$out/b.exr"
  refused "plan: environment $f" "$f.exr" plan --env "$in/$f.exr" --brdf "$in/ggx.yaml" --max-error 5%
done
for f in maps-truncated maps-flipped; do
  refused "info: $f" "$f.exr" info "$in/$f.exr"
  refused "blend: $f" "$f.exr" blend "$in/$f.exr" "$out/bl.exr"
  refused "render: $f" "$f.exr" render --maps "$in/$f.exr" --mesh "$in/octa.obj" "$out/r.png" --size 16x16
  refused "compare: $f" "$f.exr" compare "$in/$f.exr" "$in/maps-good.exr"
  refused "probe: $f" "$f.exr" probe "$in/$f.exr" --out "$out/p.exr"
done
refused "blend: a folder" "folder.exr" blend "$in/folder.exr" "$out/bl.exr"
refused "blend: a FIFO" "fifo.exr" blend "$in/fifo.exr" "$out/bl.exr"
refused "extract: a FIFO" "fifo.exr" extract "$in/fifo.exr" --lens "$in/lens.cameramodel" --out "$out/e.exr"
refused "extract: a truncated lens" "truncated.cameramodel" extract "$in/shoot-hdr/north.exr" --lens "$in/truncated.cameramodel" --out "$out/e.exr"
for f in empty text folder fifo; do
  refused "balls: $f" "$f.exr" balls "$in/$f.exr" --picture "$out/balls.png"
done
refused "balls: a truncated lens" "truncated.cameramodel" balls "$in/shoot-hdr/north.exr" --lens "$in/truncated.cameramodel"
refused "orient: a FIFO" "fifo.exr" orient "$in/fifo.exr" "$in/shoot-hdr/north.exr" --lens "$in/lens.cameramodel" --out "$out/p.yaml"
refused "render: a truncated glb" "truncated.glb" render --maps "$in/maps-good.exr" --mesh "$in/truncated.glb" "$out/r.png" --size 16x16
refused "render: an OBJ face past the vertices" "bad-index.obj" render --maps "$in/maps-good.exr" --mesh "$in/bad-index.obj" "$out/r.png" --size 16x16
refused "reference: a truncated glb" "truncated.glb" reference --mesh "$in/truncated.glb" --env "$in/env-good.exr" --brdf "$in/ggx.yaml" --size 16x16 "$out/ref.exr"

# ---- values no computation can use: refused, or zeroed on request with finite outputs
for v in nan inf minus-inf flt-max; do
  refused "convert: env-$v" "env-$v.exr" convert "$in/env-$v.exr" "$out/c.exr" --to cube --size 8
  refused "bake: env-$v" "env-$v.exr" bake --env "$in/env-$v.exr" --brdf "$in/lambert.yaml" --method sh --res 8 "$out/b.exr"
  refused "reference: env-$v" "env-$v.exr" reference --mesh "$in/octa.obj" --env "$in/env-$v.exr" --brdf "$in/ggx.yaml" --size 16x16 "$out/ref.exr"
  refused "compare: env-$v" "env-$v.exr" compare "$in/env-$v.exr" "$in/env-good.exr"
  refused "blend: maps-$v" "maps-$v.exr" blend "$in/maps-$v.exr" "$out/bl.exr"
  refused "render: maps-$v" "maps-$v.exr" render --maps "$in/maps-$v.exr" --mesh "$in/octa.obj" "$out/r.png" --size 16x16
  refused "compare: maps-$v" "maps-$v.exr" compare "$in/maps-$v.exr" "$in/maps-good.exr"
  accepted "convert --sanitize: env-$v" convert "$in/env-$v.exr" "$out/c-$v.exr" --to cube --size 8 --sanitize -q
  finite_output "convert --sanitize: env-$v" "$out/c-$v.exr"
  accepted "bake --sanitize: env-$v" bake --env "$in/env-$v.exr" --brdf "$in/lambert.yaml" --method sh --res 8 --sanitize -q "$out/b-$v.exr"
  finite_output "bake --sanitize: env-$v" "$out/b-$v.exr"
  accepted "blend --sanitize: maps-$v" blend "$in/maps-$v.exr" "$out/bl-$v.exr" --view 0.2 0.3 0.9 --sanitize
  finite_output "blend --sanitize: maps-$v" "$out/bl-$v.exr"
done
refused "probe: confidences outside [0, 1]" "maps-confidence.exr" probe "$in/maps-confidence.exr" --out "$out/p.exr"
refused "blend: confidences outside [0, 1]" "maps-confidence.exr" blend "$in/maps-confidence.exr" "$out/bl.exr"
accepted "info reports a map set's unusable values" info "$in/maps-nan.exr" --json "$out/info-nan.json"
check "info: the unusable value is counted" python3 -c "import json; assert json.load(open('$out/info-nan.json'))['unusable_values'] == 1"
accepted "convert: negative ringing is kept (reported by info)" convert "$in/env-negative.exr" "$out/c-neg.exr" --to octahedral --size 8 -q

# ---- degenerate but valid shapes
refused "blend: 1x1 maps (a source needs 2x2 texels)" "maps-1x1.exr" blend "$in/maps-1x1.exr" "$out/bl-1x1.exr" --view 0.1 0.2 0.97
accepted "blend: a one-view set" blend "$in/maps-one-view.exr" "$out/bl-one.exr" --view 0.1 0.2 0.97
finite_output "blend: a one-view set" "$out/bl-one.exr"
refused "blend: two parts with one view direction" "maps-duplicate-view.exr" blend "$in/maps-duplicate-view.exr" "$out/bl.exr"
accepted "convert: a 4x2 lat-long" convert "$in/env-tiny.exr" "$out/c-tiny.exr" --to cube --size 4 -q
refused "render: a mesh of degenerate triangles only" "degenerate.obj" render --maps "$in/maps-good.exr" --mesh "$in/degenerate.obj" "$out/r.exr" --size 16x16
accepted "render: a degenerate triangle among good ones" render --maps "$in/maps-good.exr" --mesh "$in/mixed.obj" "$out/r-mixed.png" --size 16x16 -q

# ---- specs: cycles, alias bombs, unknown keys
refused "bake: a BRDF alias cycle" "cycle.yaml" bake --env "$in/env-good.exr" --brdf "$in/cycle.yaml" --res 8 "$out/b.exr"
refused "bake: a Fresnel alias cycle" "fresnel-cycle.yaml" bake --env "$in/env-good.exr" --brdf "$in/fresnel-cycle.yaml" --res 8 "$out/b.exr"
refused "reference: a BRDF alias cycle" "cycle.yaml" reference --mesh "$in/octa.obj" --env "$in/env-good.exr" --brdf "$in/cycle.yaml" --size 16x16 "$out/ref.exr"
refused "bake: an alias bomb" "bomb.yaml" bake --env "$in/env-good.exr" --brdf "$in/bomb.yaml" --res 8 "$out/b.exr"
refused "synth: an alias bomb" "bomb.yaml" synth "$in/bomb.yaml" --out "$out/s"
refused "synth: a spec cycle" "cycle.yaml" synth "$in/cycle.yaml" --out "$out/s"
refused "probe: a --fresnel cycle" "--fresnel" probe "$in/maps-good.exr" --out "$out/p.exr" --fresnel '&f {type: schlick, f0: [*f, 1, 1]}'

# ---- photo sets
refused "hdr: a truncated PNG" "2.png" hdr "$in/png-truncated" --out "$out/h"
refused "hdr: a bit-flipped PNG" "2.png" hdr "$in/png-flipped" --out "$out/h"
refused "hdr: a zero exposure" "exposure_s" hdr "$in/zero-exposure" --out "$out/h"
refused "hdr: equal exposures" "equal-exposures" hdr "$in/equal-exposures" --out "$out/h"
refused "hdr: no exposure anywhere" "0.png" hdr "$in/no-exposures" --out "$out/h"
refused "hdr: a missing photo" "3.png" hdr "$in/missing-photo" --out "$out/h"
refused "hdr: brackets of different sizes" "4.png" hdr "$in/resized" --out "$out/h"
refused "hdr: an unknown key" "photoset.colour" hdr "$in/unknown-key" --out "$out/h"
refused "hdr: an alias bomb" "photoset.yaml" hdr "$in/bomb-set" --out "$out/h"
refused "hdr: one view given twice" "--view" hdr "$in/shoot" --out "$out/h" --view north --view north
# A JPEG cut short decodes without an error in libjpeg (grey rows): refused by its missing end.
sed 's/format: png/format: jpeg/' "$in/minimal.yaml" >"$work/jpeg-spec.yaml"
"$rsibr" synth "$work/jpeg-spec.yaml" --out "$work/jpeg-shoot" -q
jpg=$(ls "$work"/jpeg-shoot/photos/view00/*.jpg | head -1)
head -c $(($(stat -c %s "$jpg") * 2 / 3)) "$jpg" >"$jpg.cut" && mv "$jpg.cut" "$jpg"
refused "hdr: a truncated JPEG" "$(basename "$jpg")" hdr "$work/jpeg-shoot/photos" --out "$out/h"
# process keeps the steps that finished (a re-run resumes from them): only its run folder may change.
mkdir -p "$out/pr"
touch "$out/pr/.keep"
refused "process: a truncated PNG (finished steps kept)" "2.png" process "$in/png-truncated" --out "$out/pr" --lens "$in/lens.cameramodel" -q
check "process: no half-written file in the run folder" no_temporaries "$out/pr"
check "process: no staging folder left" bash -c "! find '$out/pr' -name '*.tmp*' | grep -q ."
refused "calibrate: no chessboards" "chessboards" calibrate "$in/shoot" --out "$out/cam.cameramodel"

# ---- options: ranges checked before any work
refused "render: --size overflowing 32 bits" "--size" render --maps "$in/maps-good.exr" --mesh "$in/octa.obj" "$out/r.png" --size 4294967304x8
refused "render: --size 0x8" "--size" render --maps "$in/maps-good.exr" --mesh "$in/octa.obj" "$out/r.png" --size 0x8
refused "render: --fov 1e-30" "--fov" render --maps "$in/maps-good.exr" --mesh "$in/octa.obj" "$out/r.png" --size 16x16 --fov 1e-30
refused "reference: --fov 1e-30" "--fov" reference --mesh "$in/octa.obj" --env "$in/env-good.exr" --brdf "$in/ggx.yaml" --size 16x16 --fov 1e-30 "$out/ref.exr"
refused "reference: --eye 1e30,0,0" "--eye" reference --mesh "$in/octa.obj" --env "$in/env-good.exr" --brdf "$in/ggx.yaml" --size 16x16 --eye 1e30,0,0 "$out/ref.exr"
refused "render: --eye 1e30,0,0" "--eye" render --maps "$in/maps-good.exr" --mesh "$in/octa.obj" "$out/r.png" --size 16x16 --eye 1e30,0,0
refused "render: --up along the view" "--up" render --maps "$in/maps-good.exr" --mesh "$in/octa.obj" "$out/r.png" --size 16x16 --eye 0,5,0 --at 0,0,0 --up 0,1,0
refused "render: --up along --from" "--up" render --maps "$in/maps-good.exr" --mesh "$in/octa.obj" "$out/r.png" --size 16x16 --from 0,1,0 --up 0,2,0
refused "reference: --turntable 100000000" "--turntable" reference --mesh "$in/octa.obj" --env "$in/env-good.exr" --brdf "$in/ggx.yaml" --size 1x1 --turntable 100000000 "$out/ref.exr"
refused "bake: --seed 2^64" "--seed" bake --env "$in/env-good.exr" --brdf "$in/ggx.yaml" --res 8 --seed 18446744073709551616 "$out/b.exr"
refused "bake: --res 0" "--res" bake --env "$in/env-good.exr" --brdf "$in/ggx.yaml" --res 0 "$out/b.exr"
refused "extract: --ball far larger than the image" "--ball" extract "$in/shoot-hdr/north.exr" --lens "$in/lens.cameramodel" --out "$out/e.exr" --ball 48,32,100000
refused "blend: --view 0 0 0" "--view" blend "$in/maps-good.exr" "$out/bl.exr" --view 0 0 0
refused "blend: --view nan" "--view" blend "$in/maps-good.exr" "$out/bl.exr" --view nan 0 1
refused "pattern: --size 0" "--size" pattern white "$out/pt.exr" --to latlong --size 0
refused "plan: --max-error 0" "--max-error" plan --env "$in/env-good.exr" --brdf "$in/ggx.yaml" --max-error 0
refused "plan: --max-error 150%" "--max-error" plan --env "$in/env-good.exr" --brdf "$in/ggx.yaml" --max-error 150%
refused "plan: --max-error two" "--max-error" plan --env "$in/env-good.exr" --brdf "$in/ggx.yaml" --max-error two
refused "plan: --samples without --method" "--method" plan --env "$in/env-good.exr" --brdf "$in/ggx.yaml" --max-error 2% --samples 64
refused "bake: --max-error under a fixed --samples alone" "--method" bake --env "$in/env-good.exr" --brdf "$in/ggx.yaml" --max-error 2% --samples 64 "$out/b.exr"
# NaN and Inf for every kind of floating-point option (CLI11 reads them as numbers and its range
# checks let NaN through): refused naming the option, by the check every FLOAT option gets.
for v in nan inf -inf 1e999; do
  refused "blend: --rim-fade $v" "--rim-fade" blend "$in/maps-good.exr" "$out/bl.exr" --rim-fade "$v"
  refused "extract: --camera-mask-deg $v" "--camera-mask-deg" extract "$in/shoot-hdr/north.exr" --lens "$in/lens.cameramodel" --out "$out/e.exr" --camera-mask-deg "$v"
  refused "extract: --stand-mask-deg $v" "--stand-mask-deg" extract "$in/shoot-hdr/north.exr" --lens "$in/lens.cameramodel" --out "$out/e.exr" --stand-mask-deg "$v"
  refused "hdr: --ghost-sigmas $v" "--ghost-sigmas" hdr "$in/shoot" --out "$out/h" --ghost-sigmas "$v"
  refused "compare: --fail-above $v" "--fail-above" compare "$in/maps-good.exr" "$in/maps-good.exr" --fail-above "$v"
  refused "compare: --heat-max $v" "--heat-max" compare "$in/maps-good.exr" "$in/maps-good.exr" --heat-max "$v"
  refused "pattern: --sun-intensity $v" "--sun-intensity" pattern sun-sky "$out/pt.exr" --to latlong --size 8 --sun-intensity "$v"
done
refused "pattern: a sun beyond what a float map holds" "--sun-intensity" pattern sun-sky "$out/pt.exr" --to latlong --size 8 --sun-intensity 1e300
# (made files go to $made: $in is checked byte-identical at the end)
made="$work/made"
mkdir -p "$made"
# Library preconditions checked before the call: no mrcal assertion, no division by a zero focal.
refused "calibrate: a spline of 1x1 knots" "4x4 knots" calibrate "$in/shoot" --out "$out/cam.cameramodel" --model LENSMODEL_SPLINED_STEREOGRAPHIC_order=3_Nx=1_Ny=1_fov_x_deg=0
sed 's/100, 100, 47.5/0, 0, 47.5/' "$in/lens.cameramodel" >"$made/zero-focal.cameramodel"
refused "extract: a lens of zero focal length" "zero-focal.cameramodel" extract "$in/shoot-hdr/north.exr" --lens "$made/zero-focal.cameramodel" --out "$out/e.exr"
# Scenes whose radiance overflows the camera's float arithmetic: refused naming the key.
sed 's/sun_rgb: \[20000, 19000, 17000\]/sun_rgb: [1e300, 1e300, 1e300]/' "$in/minimal.yaml" >"$made/sun-1e300.yaml"
refused "synth: a sun of 1e300" "sun_rgb" synth "$made/sun-1e300.yaml" --out "$out/s"
sed 's/focal_px: 700/focal_px: 1e-30/' "$in/minimal.yaml" >"$made/tiny-focal.yaml"
refused "synth: a focal length of 1e-30 px" "focal_px" synth "$made/tiny-focal.yaml" --out "$out/s"
sed 's/^  pattern: sun_and_sky$/&\n  scale: 1e30/' "$in/minimal.yaml" >"$made/huge-scale.yaml"
refused "synth: an environment scale of 1e30" "scale" synth "$made/huge-scale.yaml" --out "$out/s"
# Lossy-compression ringing (negative values) is folded into its neighbours by default (a warning
# says how many; core/texel_audit.h): the bake runs and its values are finite.
accepted "bake: an environment with negative ringing" bake --env "$in/env-negative.exr" --brdf "$in/lambert.yaml" --res 8 -q "$out/b-neg.exr"
finite_output "bake: an environment with negative ringing" "$out/b-neg.exr"

# ---- outputs: checked together before any work, distinct from the inputs and each other
# Each line: verb | one of its inputs | its arguments.
for spec in "convert|$in/env-good.exr|$in/env-good.exr $out/c2.exr --to cube --size 8" \
            "bake|$in/lambert.yaml|--env $in/env-good.exr --brdf $in/lambert.yaml --method sh --res 8 $out/b2.exr" \
            "blend|$in/maps-good.exr|$in/maps-good.exr $out/bl2.exr" \
            "compare|$in/maps-good.exr|$in/maps-good.exr $in/maps-good.exr" \
            "info|$in/env-good.exr|$in/env-good.exr" \
            "render|$in/octa.obj|--maps $in/maps-good.exr --mesh $in/octa.obj $out/r2.png --size 16x16" \
            "reference|$in/ggx.yaml|--mesh $in/octa.obj --env $in/env-good.exr --brdf $in/ggx.yaml --size 16x16 $out/ref2.exr" \
            "hdr|$in/shoot/north/1.png|$in/shoot --out $out/h2" \
            "extract|$in/lens.cameramodel|$in/shoot-hdr/north.exr --lens $in/lens.cameramodel --out $out/e2.exr" \
            "orient|$in/north-copy.exr|$in/shoot-hdr/north.exr $in/north-copy.exr --lens $in/lens.cameramodel --out $out/p2.yaml" \
            "probe|$in/maps-good.exr|$in/maps-good.exr --out $out/p2.exr" \
            "process|$in/shoot/photoset.yaml|$in/shoot --out $out/pr2 --lens $in/lens.cameramodel -q" \
            "synth|$in/minimal.yaml|$in/minimal.yaml --out $out/s2 -q" \
            "plan|$in/lambert.yaml|--env $in/env-good.exr --brdf $in/lambert.yaml --max-error 5% --views icosa --res 8 --method sh"; do
  verb=${spec%%|*}
  rest=${spec#*|}
  input=${rest%%|*}
  read -r -a args <<<"${rest#*|}"
  refused "$verb: --json names an input" "output would overwrite the input" "$verb" "${args[@]}" --json "$input"
  refused "$verb: --json in a missing folder" "nofolder" "$verb" "${args[@]}" --json "$out/nofolder/s.json"
  refused "$verb: --json is a folder" "is a folder" "$verb" "${args[@]}" --json "$in/folder.exr"
  refused "$verb: --json is a FIFO" "fifo.exr: is not a regular file" "$verb" "${args[@]}" --json "$in/fifo.exr"
done
refused "pattern: --json is a folder" "is a folder" pattern white "$out/pt2.exr" --to latlong --size 8 --json "$in/folder.exr"
refused "convert: --json is the output" "named twice" convert "$in/env-good.exr" "$out/c3.exr" --to cube --size 8 --json "$out/c3.exr"
refused "blend: --preview is the output" "named twice" blend "$in/maps-good.exr" "$out/bl3.exr" --preview "$out/bl3.exr"
refused "convert: the output is the input by another spelling" "output would overwrite the input" convert "$in/env-good.exr" "$in/../in/env-good.exr" --to cube --size 8
ln "$in/env-good.exr" "$work/hardlink.exr"
refused "convert: the output is a hard link to the input" "output would overwrite the input" convert "$in/env-good.exr" "$work/hardlink.exr" --to cube --size 8
rm "$work/hardlink.exr"

# ---- a full file system (a 64 KiB tmpfs, when this machine lets root mount one)
full="$work/full"
mkdir -p "$full"
if mount -t tmpfs -o size=64k tmpfs "$full" 2>/dev/null; then
  trap 'umount "$full" 2>/dev/null; rm -rf "$work"' EXIT
  head -c 40000 /dev/zero >"$full/ballast"
  refused "convert: the output's disk is full" "big.exr" convert "$in/env-good.exr" "$full/big.exr" --to cube --size 128
  head -c 20000 /dev/zero >"$full/ballast2"  # one 4 KiB page left: the preview fits, the summary does not
  refused "convert: the summary's disk is full" "s.json" convert "$in/env-good.exr" "$out/ok.exr" --to cube --size 8 --preview "$full/p.png" --json "$full/s.json" --quiet
  check "a full disk leaves no temporaries" test "$(ls -A "$full" | tr '\n' ' ')" = "ballast ballast2 "
  umount "$full"
else
  echo "bad-input-battery: cannot mount a tmpfs here; the full-disk cases are skipped"
fi

find "$in" -type f -exec sha256sum {} + | sort >"$work/inputs-after.sha"
check "every input is byte-identical" diff "$work/inputs.sha" "$work/inputs-after.sha"
finish bad-input-battery
