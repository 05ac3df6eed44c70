#!/usr/bin/env bash
# Names read from input files never become paths outside the output folder: photo sets, scene
# specs, pose files and image headers whose view or ball names hold traversals, absolute paths,
# folder references, names equal up to letter case, control characters, 10,000 characters or bytes
# that are not UTF-8, given to hdr, process, extract, orient and synth. Every one is refused with
# one line naming the file and the key, before anything is written, and nothing appears anywhere
# outside the output folder. Free text (a camera name) that is not UTF-8 or holds markup is kept:
# the JSON stays valid UTF-8 and the HTML report shows it as text.
# Usage: hostile_names_test.sh /path/to/rsibr
set -u
rsibr=$1
here=$(cd "$(dirname "$0")" && pwd)
. "$here/contract_lib.sh"

# Everything under $work except the harness's scratch files, one path a line.
tree() { (cd "$work" && find . -mindepth 1 ! -name out ! -name err ! -name before ! -name after | sort); }
# nothing_written NAME COMMAND...: the command leaves the tree under $work exactly as it was.
nothing_written() {
  local name=$1; shift
  tree >"$work/before"
  "$@" >/dev/null 2>&1
  tree >"$work/after"
  if cmp -s "$work/before" "$work/after"; then pass=$((pass + 1)); else
    fail=$((fail + 1)); echo "FAILED: $name wrote:"; diff "$work/before" "$work/after" | head -5
  fi
}

python3 "$here/bracket_shoot.py" "$work/shoot"
mkdir -p "$work/trav/t/a"
# hostile_set FOLDER VIEW-NAME...: a photo set of the shoot's brackets under views of those names
# (written YAML double-quoted, so "\t" is a tab; "\\xFF" in a name is written as the raw byte 0xFF).
hostile_set() {
  local dir=$1; shift
  mkdir -p "$dir"
  python3 - "$work/shoot" "$dir" "$@" <<'PY'
import sys
shoot, out, names = sys.argv[1], sys.argv[2], sys.argv[3:]
lines = [b"rsibr_photoset: 1", b"views:"]
for name in names:
    raw = name.encode().replace(b"\\\\xFF", b"\xff")
    lines += [b'  - name: "' + raw + b'"', b"    brackets:"]
    lines += [b"      - {file: %s/north/%d.png, exposure_s: %r}" % (shoot.encode(), j, t)
              for j, t in enumerate([1 / 256, 1 / 64, 1 / 16, 1 / 4, 1.0])]
open(out + "/photoset.yaml", "wb").write(b"\n".join(lines) + b"\n")
PY
}

long=$(printf 'v%.0s' $(seq 10000))
i=0
while IFS='|' read -r label needle names; do
  i=$((i + 1))
  set="$work/set$i"
  eval "hostile_set '$set' $names"
  for verb in hdr process; do
    expect_error "$verb: view named $label" "photoset.yaml: photoset.views\[$needle" $verb "$set" --out "$work/trav/t/a/$verb$i" -q
    nothing_written "$verb: view named $label writes nothing" "$rsibr" $verb "$set" --out "$work/trav/t/a/$verb$i" -q
  done
done <<CASES
a traversal|0\].name: a name starting with '.'|'../../esc/stolen'
a path below the folder|0\].name: a name containing a path separator|'v/../../../esc2/stolen'
an absolute path|0\].name: a name starting with a path separator|'$work/abs/escaped'
.|0\].name: a name that is a folder reference|'.'
..|0\].name: a name that is a folder reference|'..'
a hidden file|0\].name: a name starting with '.'|'.exr'
an option|0\].name: a name starting with '-'|'-v'
North and north|1\].name: view name 'north' clashes with 'North'|'North' 'north'
a control character|0\].name: a name containing a control character|'tab\\there'
10,000 characters|0\].name: a name of 10000 characters|'$long'
bytes that are not UTF-8|0\].name: a name containing a character that is not ASCII|'caf\\\\xFF'
markup|0\].name: a name starting with '<'|'<script>alert(1)</script>'
CASES
check "no file escaped the output folders" test ! -e "$work/esc" -a ! -e "$work/esc2" -a ! -e "$work/abs" -a ! -e "$work/trav/t/esc"

# Ball names (photo set) and view names (pose files) are checked the same way.
hostile_set "$work/balls" north
sed -i '1a balls: [{name: "../../esc/ball", kind: chrome}]' "$work/balls/photoset.yaml"
expect_error "hdr: ball named with a traversal" "photoset.balls\[0\].name: a name starting with '.'" hdr "$work/balls" --out "$work/trav/t/a/hb"
hostile_set "$work/good" north
"$rsibr" hdr "$work/good" --out "$work/good-hdr" -q --no-preview
pinhole_lens "$work/lens.cameramodel"
printf 'rsibr_poses: 1\ngauge: first-view\nviews:\n  - name: "../north"\n    world_from_cam: [1, 0, 0, 0, 1, 0, 0, 0, 1]\n    sigma_deg: 0\n' >"$work/poses.yaml"
expect_error "extract --poses: a pose file's view named with a traversal" "poses.yaml: poses.views\[0\].name: a name starting with '.'" \
  extract "$work/good-hdr/north.exr" --lens "$work/lens.cameramodel" --poses "$work/poses.yaml" --out "$work/trav/t/a/e.exr"
# An image whose header names its view "../.." (the merged view's rsibr.view patched in place).
python3 - "$work/good-hdr/north.exr" "$work/dots.exr" <<'PY'
import struct, sys
data = open(sys.argv[1], "rb").read()
key = b"rsibr.view\x00string\x00" + struct.pack("<i", 5)
assert data.count(key + b"north") == 1
open(sys.argv[2], "wb").write(data.replace(key + b"north", key + b"../.."))
PY
expect_error "orient: an image whose header names its view '../..'" "dots.exr: rsibr.view: a name starting with '.'" \
  orient "$work/dots.exr" "$work/good-hdr/north.exr" --lens "$work/lens.cameramodel" --out "$work/trav/t/a/p.yaml"
expect_error "extract: an image whose header names its view '../..'" "dots.exr: rsibr.view: a name starting with '.'" \
  extract "$work/dots.exr" --lens "$work/lens.cameramodel" --out "$work/trav/t/a/e2.exr"
check "no output after the refused pose and image names" test -z "$(ls -A "$work/trav/t/a")"

# synth: a ball named with a traversal is refused; a camera name with markup and a byte that is
# not UTF-8 is free text, carried to the photo set, the JSON and the report as valid UTF-8 text.
spec="$here/../../datasets-synthetic/minimal-grey.yaml"
sed 's/name: chrome/name: "..\/..\/esc\/ball"/' "$spec" >"$work/badball.yaml"
expect_error "synth: ball named with a traversal" "badball.yaml: scene.balls\[0\].name: a name starting with '.'" \
  synth "$work/badball.yaml" --out "$work/trav/t/a/s"
check "synth: nothing written" test ! -e "$work/trav/t/a/s" -a ! -e "$work/esc"
python3 - "$spec" "$work/markup.yaml" <<'PY'
import sys
text = open(sys.argv[1], "rb").read()
assert text.count(b"\ncamera:\n") == 1, "minimal-grey.yaml has one camera block"
name = b'  name: "<script>alert(1)</script> caf\xe9"\n'
open(sys.argv[2], "wb").write(text.replace(b"\ncamera:\n", b"\ncamera:\n" + name))
PY
"$rsibr" synth "$work/markup.yaml" --out "$work/msyn" -q
check "synth: the camera name reaches the photo set" grep -q "script" "$work/msyn/photos/photoset.yaml"
"$rsibr" hdr "$work/msyn/photos" --out "$work/mhdr" --no-preview --json "$work/mhdr.json" -q
check "hdr --json: valid UTF-8 (the camera's bad byte replaced)" python3 -c "
import json; json.load(open('$work/mhdr.json', encoding='utf-8', errors='strict'))"
"$rsibr" process "$work/msyn/photos" --out "$work/mrun" --poses "$work/msyn/truth/truth.yaml" \
  --map-size 16 --turntable 1 --size 32x24 --json "$work/mrun.json" -q >/dev/null
check "process --json: valid UTF-8" python3 -c "import json; json.load(open('$work/mrun.json', encoding='utf-8', errors='strict'))"
check "process report: the camera name shows as text, not markup" bash -c "
grep -q '&lt;script&gt;alert(1)&lt;/script&gt;' '$work/mrun/report.html' && ! grep -q '<script>alert' '$work/mrun/report.html'"
check "process report: valid UTF-8" python3 -c "open('$work/mrun/report.html', encoding='utf-8', errors='strict').read()"
check "no file escaped anywhere" test ! -e "$work/esc" -a ! -e "$work/abs"

finish hostile-names
