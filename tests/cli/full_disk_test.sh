#!/usr/bin/env bash
# Every verb that writes, onto a full file system (a small tmpfs): exit status 4, one line on
# stderr naming the output, and nothing left on the full file system but its filler. Two levels:
# no space at all, and a few KiB (headers fit, pixels do not). Needs root (mount); skipped with a
# message (exit 77) where mounting a tmpfs is not allowed.
# Usage: full_disk_test.sh /path/to/rsibr /path/to/rsibr_bad_inputs
set -u
rsibr=$1
make_bad=$2
here=$(cd "$(dirname "$0")" && pwd)
. "$here/contract_lib.sh"
in="$work/in" full="$work/full"
mkdir -p "$in" "$full"
if ! mount -t tmpfs -o size=256k tmpfs "$full" 2>/dev/null; then
  echo "SKIP: cannot mount a tmpfs here (needs root and CAP_SYS_ADMIN); the full-disk contract is untested"
  exit 77
fi
trap 'umount "$full" 2>/dev/null; [ -n "${KEEP_WORK:-}" ] || rm -rf "$work"' EXIT

# ---- fixtures, on the ordinary disk
"$make_bad" "$in"
printf 'type: lambert\nalbedo: [0.5, 0.5, 0.5]\n' >"$in/lambert.yaml"
printf 'type: ggx\nroughness: 0.3\nfresnel: {type: schlick, f0: [0.9, 0.7, 0.4]}\n' >"$in/ggx.yaml"
printf 'v 1 0 0\nv -1 0 0\nv 0 1 0\nv 0 -1 0\nv 0 0 1\nv 0 0 -1\nf 1 3 5\nf 3 2 5\nf 2 4 5\nf 4 1 5\nf 3 1 6\nf 2 3 6\nf 4 2 6\nf 1 4 6\n' >"$in/octa.obj"
sed 's/chessboards: {count: 2,/chessboards: {count: 8,/' "$here/../../datasets-synthetic/minimal.yaml" >"$in/min8.yaml"
"$rsibr" synth "$in/min8.yaml" --out "$in/syn" -q
"$rsibr" hdr "$in/syn/photos" --out "$in/hdr" -q --no-preview
"$rsibr" calibrate "$in/syn/photos" --out "$in/lens.cameramodel" -q
"$rsibr" extract "$in/hdr/view00.exr" --lens "$in/lens.cameramodel" --out "$in/chrome0.exr" --size 32 -q
printf 'jobs:\n  - [convert, in/env-good.exr, full/batch.exr, --to, cube, --size, 8]\n' >"$work/batch.yaml"

# fill LEFT_KIB: the tmpfs full but for LEFT_KIB KiB.
fill() {
  rm -rf "${full:?}"/* "$full"/.[!.]* 2>/dev/null
  dd if=/dev/zero of="$full/.fill" bs=4k 2>/dev/null
  [ "$1" -gt 0 ] && truncate -s "-$1K" "$full/.fill"
  sync
}
# complete_outputs: prints what is wrong with the files on the full disk (none may be empty, a
# temporary, or broken: EXRs must read, PNGs end with IEND, JSON must parse).
complete_outputs() {
  find "$full" -type f ! -name .fill | while read -r f; do
    case "$f" in *.tmp*) echo "a temporary left: $f"; continue ;; esac
    [ -s "$f" ] || { echo "empty: $f"; continue; }
    case "$f" in
      *.exr) "$rsibr" info "$f" >/dev/null 2>&1 || echo "unreadable: $f" ;;
      *.png) [ "$(tail -c 8 "$f" | od -An -tx1 | tr -d ' ')" = "49454e44ae426082" ] || echo "truncated: $f" ;;
      *.json) python3 -c "import json,sys; json.load(open(sys.argv[1]))" "$f" 2>/dev/null || echo "broken: $f" ;;
    esac
  done | head -3 | tr '\n' ' '
}
# on_full_disk LEFT_KIB NAME ARGS...: the whole contract for one verb. KEEP=1 in the environment:
# the verb's run folder may stay (with whole files only); LINES_OK=N: N lines on stderr;
# NEEDLE: what the message must name (default: the full file system's path); STATUS: the exit
# status wanted (default 4, an output that could not be written).
on_full_disk() {
  local left=$1 name="$2 ($1 KiB free)" keep=${KEEP:-}; shift 2
  fill "$left"
  timeout 300 "$rsibr" "$@" >"$work/out" 2>"$work/err"
  local rc=$?
  local lines; lines=$(wc -l <"$work/err")
  local left_over; left_over=$(ls -A "$full" | grep -v '^\.fill$' | head -3 | tr '\n' ' ')
  local why=""
  if [ "$rc" -eq 124 ]; then why="timed out"
  elif [ "$rc" -ge 128 ]; then why="killed by signal $((rc - 128))"
  elif [ "$rc" -eq 0 ] && [ "$left" -eq 0 ]; then why="exit 0"
  elif [ "$rc" -eq 0 ]; then why=$(complete_outputs)  # it fitted: every file must be whole
  elif [ "$rc" -ne "${STATUS:-4}" ]; then why="exit $rc, not ${STATUS:-4} (an output could not be written)"
  elif [ "$lines" -ne "${LINES_OK:-1}" ]; then why="$lines lines on stderr"
  elif ! grep -q -- "${NEEDLE:-$full}" "$work/err"; then why="the message does not name the output"
  elif [ -n "$keep" ]; then why=$(complete_outputs)  # a run folder keeps what finished
  elif [ -n "$left_over" ]; then why="left on the full disk: $left_over"
  fi
  if [ -z "$why" ]; then pass=$((pass + 1)); else
    fail=$((fail + 1)); echo "FAILED: $name: $why"; head -3 "$work/err"
  fi
}

for left in 0 8; do
  on_full_disk "$left" "pattern" pattern sun-sky "$full/p.exr" --to latlong --size 64
  on_full_disk "$left" "convert" convert "$in/env-good.exr" "$full/c.exr" --to cube --size 32 -q
  on_full_disk "$left" "convert --preview" convert "$in/env-good.exr" "$work/c-ok.exr" --to cube --size 32 --preview "$full/c.png" -q
  on_full_disk "$left" "info --json" info "$in/env-good.exr" --json "$full/info.json"
  on_full_disk "$left" "bake" bake --env "$in/env-good.exr" --brdf "$in/lambert.yaml" --res 32 --method sh -q "$full/b.exr"
  on_full_disk "$left" "blend" blend "$in/maps-good.exr" "$full/bl.exr" --view 0.2 0.3 0.9 --size 64
  on_full_disk "$left" "reference" reference --mesh "$in/octa.obj" --env "$in/env-good.exr" --brdf "$in/ggx.yaml" --size 64x64 --spp 1 -q "$full/ref.exr"
  on_full_disk "$left" "render" render --maps "$in/maps-good.exr" --mesh "$in/octa.obj" "$full/r.png" --size 64x64 -q
  on_full_disk "$left" "compare --json" compare "$in/maps-good.exr" "$in/maps-good.exr" -q --json "$full/cmp.json"
  on_full_disk "$left" "compare --out" compare "$in/maps-good.exr" "$in/maps-good.exr" -q --out "$full/cmp"
  on_full_disk "$left" "synth" synth "$in/min8.yaml" --out "$full/syn" -q
  on_full_disk "$left" "hdr" hdr "$in/syn/photos" --out "$full/hdr" -q
  on_full_disk "$left" "calibrate" calibrate "$in/syn/photos" --out "$full/lens.cameramodel" -q
  on_full_disk "$left" "extract" extract "$in/hdr/view00.exr" --lens "$in/lens.cameramodel" --out "$full/e.exr" --size 64 -q
  on_full_disk "$left" "balls --picture" balls "$in/hdr/view00.exr" --lens "$in/lens.cameramodel" --picture "$full/balls.png"
  on_full_disk "$left" "probe" probe "$in/chrome0.exr" --out "$full/probe.exr" --width 64 -q
  on_full_disk "$left" "plan --json" plan --env "$in/env-good.exr" --brdf "$in/lambert.yaml" --max-error 20% --views octa --res 8 --json "$full/plan.json"
  STATUS=1 NEEDLE=full/batch.exr LINES_OK=2 on_full_disk "$left" "batch (the job's line and the summary)" batch "$work/batch.yaml" -q
  KEEP=1 on_full_disk "$left" "process" process "$in/syn/photos" --out "$full/run" -q
done
finish "full disk"
