#!/usr/bin/env bash
# End-to-end checks of the dynsub command line: what a person sees when things
# go right and when they go wrong. Needs DYNSUB (the executable) and DATA.
set -u
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
failures=0
check() {  # check NAME CONDITION...
  local name=$1; shift
  if "$@"; then echo "ok: $name"; else echo "FAILED: $name"; failures=$((failures + 1)); fi
}
# expect_error NAME EXPECTED_CODE MESSAGE_FRAGMENT OUTPUT_FILE COMMAND...
expect_error() {
  local name=$1 code=$2 fragment=$3 output=$4; shift 4
  "$@" >"$work/stdout" 2>"$work/stderr"
  local rc=$?
  check "$name: exit code $code (got $rc)" test "$rc" -eq "$code"
  check "$name: message mentions '$fragment'" grep -q -- "$fragment" "$work/stderr"
  check "$name: no output file" test ! -e "$output"
  check "$name: no temporary file left" test -z "$(ls -A "$work" | grep '^\.tmp' || true)"
}

"$DYNSUB" --help >"$work/help" 2>&1
check "dynsub --help lists limit" grep -q "limit" "$work/help"
"$DYNSUB" limit --help >"$work/help" 2>&1
check "dynsub limit --help explains --samples-per-face" grep -q -- "--samples-per-face" "$work/help"

"$DYNSUB" limit "$DATA/Meshes/torus.obj" --samples-per-face 4 --out "$work/torus.vtp" >"$work/stdout"
check "limit writes the torus" test -s "$work/torus.vtp"
check "limit reports the triangle count" grep -q "1024 triangles" "$work/stdout"
for extension in obj ply stl; do
  "$DYNSUB" limit "$DATA/Meshes/sheet.obj" --samples-per-face 2 --out "$work/sheet.$extension" >/dev/null
  check "limit writes .$extension" test -s "$work/sheet.$extension"
done

expect_error "missing mesh" 1 "no such file" "$work/a.vtp" "$DYNSUB" limit "$work/none.obj" --out "$work/a.vtp"
printf 'v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nv 0 -1 0\nf 1 2 3\nf 2 1 4\nf 1 2 5\n' >"$work/fin.obj"
expect_error "non-manifold mesh" 1 "not manifold" "$work/b.vtp" "$DYNSUB" limit "$work/fin.obj" --out "$work/b.vtp"
printf 'v 0 0 0\nv 1 nan 0\n' >"$work/nan.obj"
expect_error "unparsable number" 1 "nan.obj" "$work/c.vtp" "$DYNSUB" limit "$work/nan.obj" --out "$work/c.vtp"
: >"$work/empty.obj"
expect_error "empty mesh" 1 "no vertices" "$work/d.vtp" "$DYNSUB" limit "$work/empty.obj" --out "$work/d.vtp"
expect_error "unknown output format" 1 "unknown surface format" "$work/e.xyz" \
  "$DYNSUB" limit "$DATA/Meshes/cube.obj" --out "$work/e.xyz"
expect_error "missing output directory" 1 "does not exist" "$work/no/f.vtp" \
  "$DYNSUB" limit "$DATA/Meshes/cube.obj" --out "$work/no/f.vtp"
expect_error "impossible sample count" 2 "samples-per-face" "$work/g.vtp" \
  "$DYNSUB" limit "$DATA/Meshes/cube.obj" --samples-per-face 0 --out "$work/g.vtp"
expect_error "unknown standard mesh" 2 "NAME" "$work/h.obj" "$DYNSUB" mesh sphere --out "$work/h.obj"

if [ "$failures" -gt 0 ]; then echo "$failures check(s) failed"; exit 1; fi
echo "all command-line checks passed"
