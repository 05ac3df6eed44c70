# Shared by the command-line contract scripts (sourced): a scratch folder removed on exit, pass and
# fail counters, `check NAME COMMAND...`, `expect_error NAME NEEDLE ARGS...` (rsibr must exit
# non-zero with exactly one line on stderr that contains NEEDLE), `no_temporaries FOLDER`, and
# `finish` (prints the counts; the script's exit status).
# Needs $rsibr set to the binary under test.
work=$(mktemp -d)
trap '[ -n "${KEEP_WORK:-}" ] || rm -rf "$work"' EXIT
pass=0 fail=0
check() {  # check NAME CONDITION-COMMAND...
  local name=$1; shift
  if "$@"; then pass=$((pass + 1)); else fail=$((fail + 1)); echo "FAILED: $name"; fi
}
# Runs rsibr expecting failure: non-zero exit, exactly one line on stderr that names $2.
expect_error() {
  local name=$1 needle=$2; shift 2
  "$rsibr" "$@" >"$work/out" 2>"$work/err"
  local rc=$?
  local lines; lines=$(wc -l <"$work/err")
  if [ "$rc" -ne 0 ] && [ "$lines" -eq 1 ] && grep -q -- "$needle" "$work/err"; then
    pass=$((pass + 1))
  else
    fail=$((fail + 1)); echo "FAILED: $name (exit $rc, $lines lines):"; cat "$work/err"
  fi
}
# pinhole_lens FILE: the mrcal pinhole model of the scripts' 96x64 test images.
pinhole_lens() {
  cat >"$1" <<'CM'
{
    'lensmodel':  'LENSMODEL_PINHOLE',
    'intrinsics': [ 100, 100, 47.5, 31.5 ],
    'imagersize': [ 96, 64 ],
    'extrinsics': [ 0, 0, 0, 0, 0, 0 ],
}
CM
}
no_temporaries() { ! ls -A "$1" | grep -q '\.tmp'; }
finish() {
  echo "$1: $pass passed, $fail failed"
  [ "$fail" -eq 0 ]
}
