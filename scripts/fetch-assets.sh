#!/usr/bin/env bash
# Fetches the npm package @pmndrs/assets (CC0-1.0) and decodes the real-world
# assets rsibr uses from it into a cache folder:
#   hdri/<name>.exr.js   (ES module: export default 'data:application/exr;base64,...')
#       -> <cache>/assets/hdri/<name>.exr
#   models/<name>.glb.js (ES module: export default 'data:model/gltf-binary;base64,...')
#       -> <cache>/assets/models/<name>.glb
# plus <cache>/assets/MANIFEST.txt (package version, tarball sha512, and size +
# sha256 of every output file).
#
# Cache folder: $RSIBR_CACHE_DIR/assets if RSIBR_CACHE_DIR is set, otherwise
# <repo>/cache/assets (git-ignored).
# Package version: pinned to 1.7.0 (tarball sha512 checked); override with
# RSIBR_ASSETS_VERSION=<version|latest> (no tarball pin then; npm's own
# registry integrity check still applies).
#
# Idempotent: when MANIFEST.txt is for the same package version and every file
# it lists verifies (size + sha256), nothing is fetched. Every output is written
# under a temporary name and renamed into place; the manifest is written last,
# so an interrupted run is redone by the next one. The package is packed into a
# temporary directory (npm pack), never into a node_modules in the repo.
# Errors: one line "fetch-assets: error: ..." on stderr, exit status 1.
# Needs: bash, npm + node (>= 16), tar, gzip, sha256sum, sha512sum, flock.
set -euo pipefail

readonly PKG="@pmndrs/assets"
readonly PINNED_VERSION="1.7.0"
readonly PINNED_SHA512="cc798a352fb726fbbd2b7cc90507d840a4fd3e7f4842df2cd2afde242dc25caa56a7283a2016be8af37d3600e7f9f0d3d80563521d98459fff19752e7ae01d0a"

die() { printf 'fetch-assets: error: %s\n' "$*" >&2; exit 1; }
say() { printf 'fetch-assets: %s\n' "$*"; }

for tool in npm node tar gzip sha256sum sha512sum flock; do
  command -v "$tool" >/dev/null 2>&1 || die "required tool '$tool' not found in PATH"
done

repo_root="$(cd -- "$(dirname -- "${BASH_SOURCE[0]}")/.." && pwd)"
if [[ -n "${RSIBR_CACHE_DIR:-}" ]]; then
  out_dir="${RSIBR_CACHE_DIR%/}/assets"
else
  out_dir="$repo_root/cache/assets"
fi
manifest="$out_dir/MANIFEST.txt"

mkdir -p "$out_dir" || die "cannot create cache folder $out_dir"
out_dir="$(cd -- "$out_dir" && pwd)"
manifest="$out_dir/MANIFEST.txt"

# One run at a time per cache folder.
exec 9>"$out_dir/.fetch-assets.lock" || die "cannot open lock file in $out_dir"
flock -w 600 9 || die "another fetch-assets run holds $out_dir/.fetch-assets.lock"

work=""
stage=""
# shellcheck disable=SC2317  # invoked via trap
cleanup() {
  if [[ -n "$work" && -d "$work" ]]; then rm -rf -- "$work"; fi
  if [[ -n "$stage" && -d "$stage" ]]; then rm -rf -- "$stage"; fi
  return 0
}
trap cleanup EXIT
trap 'exit 130' INT TERM
work="$(mktemp -d "${TMPDIR:-/tmp}/rsibr-fetch-assets.XXXXXX")" || die "cannot create a temporary directory"

# npm runs inside the temp dir with quiet logging; its messages go to a file and
# only its first error line is shown on failure.
npm_run() {
  (cd -- "$work" && npm --no-fund --no-audit --loglevel=error \
     --fetch-retries="${RSIBR_NPM_RETRIES:-1}" --fetch-timeout="${RSIBR_NPM_TIMEOUT_MS:-30000}" \
     "$@" 2>"$work/npm.err")
}
npm_error_line() {
  local code detail hint=""
  code="$(sed -n 's/^npm \(error\|ERR!\) code \(.*\)$/\2/p' "$work/npm.err" 2>/dev/null | head -n1)"
  detail="$(grep -E '^npm (error|ERR!) ' "$work/npm.err" 2>/dev/null \
    | sed -E 's/^npm (error|ERR!) +//' \
    | grep -vE '^(code|syscall|errno|A complete log) |^\s*$' | head -n1 || true)"
  [[ -z "$code$detail" ]] && detail="$(grep -vi 'warn' "$work/npm.err" 2>/dev/null | grep -m1 . || true)"
  case "$code" in
    ECONNREFUSED|ENOTFOUND|ETIMEDOUT|EAI_AGAIN|ECONNRESET|ENETUNREACH|EHOSTUNREACH|ERR_SOCKET_TIMEOUT|FETCH_ERROR)
      hint="npm registry unreachable: " ;;
  esac
  printf '%s%s' "$hint" "${code:+$code: }${detail:-no message from npm}" | tr -s '[:space:]' ' '
}

# --- resolve the version ------------------------------------------------------
want="${RSIBR_ASSETS_VERSION:-$PINNED_VERSION}"
if [[ "$want" =~ ^[0-9]+\.[0-9]+\.[0-9]+$ ]]; then
  version="$want"
else
  version="$(npm_run view "$PKG@$want" version --json)" \
    || die "npm view $PKG@$want failed: $(npm_error_line)"
  version="$(printf '%s' "$version" | tr -d '"[:space:]')"
  [[ "$version" =~ ^[0-9]+\.[0-9]+\.[0-9]+([-+][0-9A-Za-z.-]+)?$ ]] \
    || die "npm view $PKG@$want returned no single version ('$version')"
fi

# --- idempotence: verify an existing manifest ---------------------------------
# Manifest lines: "package NAME", "version V", "tarball_sha512 H", "license L",
# "file SIZE SHA256 RELPATH"; '#' starts a comment.
verify_manifest() {
  [[ -f "$manifest" ]] || return 1
  local kind a b c mver="" nfiles=0 size sum
  while read -r kind a b c; do
    case "$kind" in
      version) mver="$a" ;;
      file)
        [[ "$a" =~ ^[0-9]+$ && "$b" =~ ^[0-9a-f]{64}$ && -n "$c" ]] || return 1
        [[ -f "$out_dir/$c" ]] || return 1
        size="$(stat -c %s -- "$out_dir/$c")" || return 1
        [[ "$size" == "$a" ]] || return 1
        sum="$(sha256sum -- "$out_dir/$c" | cut -d' ' -f1)" || return 1
        [[ "$sum" == "$b" ]] || return 1
        nfiles=$((nfiles + 1)) ;;
    esac
  done <"$manifest"
  [[ "$mver" == "$version" && $nfiles -gt 0 ]]
}

if verify_manifest; then
  say "up to date: $PKG@$version in $out_dir ($(grep -c '^file ' "$manifest") files verified), nothing to do"
  exit 0
fi

# --- fetch ---------------------------------------------------------------------
say "fetching $PKG@$version ..."
npm_run pack "$PKG@$version" --pack-destination "$work" >/dev/null \
  || die "npm pack $PKG@$version failed: $(npm_error_line)"
tarball="$(find "$work" -maxdepth 1 -name '*.tgz' -print -quit)"
[[ -n "$tarball" && -s "$tarball" ]] || die "npm pack $PKG@$version produced no tarball"
tar_sha512="$(sha512sum -- "$tarball" | cut -d' ' -f1)"
if [[ "$version" == "$PINNED_VERSION" && "$tar_sha512" != "$PINNED_SHA512" ]]; then
  die "tarball sha512 mismatch for $PKG@$version (got $tar_sha512)"
fi

mkdir -p "$work/pkg"
tar -xzf "$tarball" -C "$work/pkg" --no-same-owner --no-same-permissions \
    package/package.json package/LICENSE package/hdri package/models \
  || die "cannot extract hdri/ and models/ from $(basename -- "$tarball")"
pkgdir="$work/pkg/package"
license="$(node -e 'const p=require(process.argv[1]); if(!p.version) process.exit(1); process.stdout.write((p.license||"UNKNOWN")+" "+p.version)' "$pkgdir/package.json")" \
  || die "cannot read package.json of $PKG@$version"
pkg_version="${license##* }"; license="${license% *}"
[[ "$pkg_version" == "$version" ]] || die "tarball holds version $pkg_version, expected $version"

# --- decode into a staging dir on the same filesystem (atomic renames) ---------
stage="$out_dir/.staging.$$"
rm -rf -- "$stage"
mkdir -p "$stage/hdri" "$stage/models"

# Inputs: hdri/*.exr.js, hdri/*.exr, models/*.glb.js, models/*.glb (whatever the
# package ships). Decoded/copied and validated by one node process.
shopt -s nullglob
pairs=()
for f in "$pkgdir"/hdri/*.exr.js "$pkgdir"/hdri/*.exr "$pkgdir"/models/*.glb.js "$pkgdir"/models/*.glb; do
  sub="$(basename -- "$(dirname -- "$f")")"
  name="$(basename -- "$f")"; name="${name%.js}"
  [[ "$name" =~ ^[A-Za-z0-9][A-Za-z0-9._-]*\.(exr|glb)$ ]] || die "unexpected asset file name '$sub/$name'"
  pairs+=("$f" "$stage/$sub/$name")
done
shopt -u nullglob
n_hdri=0; n_glb=0
for ((i = 1; i < ${#pairs[@]}; i += 2)); do
  case "${pairs[i]}" in *.exr) n_hdri=$((n_hdri + 1)) ;; *.glb) n_glb=$((n_glb + 1)) ;; esac
done
((n_hdri > 0)) || die "$PKG@$version has no hdri/*.exr(.js) files"
((n_glb > 0)) || die "$PKG@$version has no models/*.glb(.js) files"

cat >"$work/decode.cjs" <<'NODE'
'use strict';
const fs = require('fs');
const path = require('path');
const args = process.argv.slice(2);
// Strict shape of a generated asset module: one default export of a base64 data URI.
const re = /^\s*export\s+default\s+(['"])data:([A-Za-z0-9.+-]+\/[A-Za-z0-9.+-]+);base64,([A-Za-z0-9+/]*={0,2})\1\s*;?\s*$/;
const fail = (msg) => { process.stderr.write('fetch-assets: error: ' + msg + '\n'); process.exit(1); };
try {
for (let i = 0; i + 1 < args.length; i += 2) {
  const src = args[i], dst = args[i + 1];
  const rel = path.basename(path.dirname(src)) + '/' + path.basename(src);
  let buf;
  if (src.endsWith('.js')) {
    const text = fs.readFileSync(src, 'utf8');
    const m = re.exec(text);
    if (!m) fail(`${rel}: not an 'export default "data:<mime>;base64,..."' module`);
    const b64 = m[3];
    if (b64.length % 4 !== 0) fail(`${rel}: base64 payload length ${b64.length} is not a multiple of 4`);
    buf = Buffer.from(b64, 'base64');
    if (buf.toString('base64') !== b64) fail(`${rel}: base64 payload does not round-trip (corrupt)`);
  } else {
    buf = fs.readFileSync(src);
  }
  if (dst.endsWith('.exr')) {
    // OpenEXR magic 76 2f 31 01, then a 4-byte version field (low byte = 2).
    if (buf.length < 8 || buf[0] !== 0x76 || buf[1] !== 0x2f || buf[2] !== 0x31 || buf[3] !== 0x01)
      fail(`${rel}: decoded data lacks the OpenEXR magic 76 2f 31 01`);
    if (buf[4] !== 2) fail(`${rel}: unsupported OpenEXR version ${buf[4]}`);
  } else if (dst.endsWith('.glb')) {
    // glTF binary header: "glTF", uint32 version (2), uint32 total length.
    if (buf.length < 12 || buf.toString('latin1', 0, 4) !== 'glTF')
      fail(`${rel}: decoded data lacks the "glTF" magic`);
    const ver = buf.readUInt32LE(4), len = buf.readUInt32LE(8);
    if (ver !== 2) fail(`${rel}: unsupported glTF binary version ${ver}`);
    if (len !== buf.length) fail(`${rel}: glTF header length ${len} != decoded size ${buf.length}`);
  } else {
    fail(`${rel}: unknown output type`);
  }
  fs.writeFileSync(dst, buf);
}
} catch (e) { fail('decoding failed: ' + (e && e.message ? e.message : String(e)).split('\n')[0]); }
NODE
# The decoder prints its own single error line.
node "$work/decode.cjs" "${pairs[@]}" || exit 1

# --- install: drop the old manifest first, then rename each file into place ----
rm -f -- "$manifest"
manifest_tmp="$stage/MANIFEST.txt"
{
  printf '# %s assets decoded by scripts/fetch-assets.sh (do not edit)\n' "$PKG"
  printf '# line format: file <size-bytes> <sha256> <path relative to this folder>\n'
  printf 'package %s\n' "$PKG"
  printf 'version %s\n' "$version"
  printf 'tarball_sha512 %s\n' "$tar_sha512"
  printf 'license %s\n' "$license"
} >"$manifest_tmp"

for ((i = 1; i < ${#pairs[@]}; i += 2)); do
  staged="${pairs[i]}"
  rel="${staged#"$stage"/}"
  size="$(stat -c %s -- "$staged")"
  sum="$(sha256sum -- "$staged" | cut -d' ' -f1)"
  mkdir -p "$out_dir/$(dirname -- "$rel")"
  mv -f -- "$staged" "$out_dir/$rel" || die "cannot move $rel into $out_dir"
  printf 'file %s %s %s\n' "$size" "$sum" "$rel" >>"$manifest_tmp"
done
mv -f -- "$manifest_tmp" "$manifest" || die "cannot write $manifest"

verify_manifest || die "verification of $out_dir failed right after writing it"
say "done: $PKG@$version ($license) -> $out_dir: $n_hdri EXR, $n_glb GLB, MANIFEST.txt"
