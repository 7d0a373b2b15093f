# Sourced by the command-line test scripts: one named check at a time, failures counted.
# A failed check returns 1, so that `check ... || show-the-log` shows why.
failures=0
check() {  # check NAME CONDITION...
  local name=$1; shift
  if "$@"; then echo "ok: $name"; else echo "FAILED: $name"; failures=$((failures + 1)); return 1; fi
}
# expect_error NAME EXPECTED_CODE MESSAGE_FRAGMENT OUTPUT_FILE COMMAND...: the
# command fails with that exit code, says the fragment on stderr, and leaves
# neither OUTPUT_FILE nor a temporary file in $work (the sourcing script's
# scratch directory).
expect_error() {
  local name=$1 code=$2 fragment=$3 output=$4; shift 4
  "$@" >"$work/stdout" 2>"$work/stderr"
  local rc=$?
  check "$name: exit code $code (got $rc)" test "$rc" -eq "$code"
  check "$name: message mentions '$fragment'" grep -q -- "$fragment" "$work/stderr"
  check "$name: no output file" test ! -e "$output"
  check "$name: no temporary file left" test -z "$(ls -A "$work" | grep '^\.tmp' || true)"
}
# require_colin27: the Colin27 MRI and its AAL atlas (Debian package
# mricron-data) in $templates, or the script stops, saying what to install.
require_colin27() {
  templates=/usr/share/mricron/templates
  if [ ! -f "$templates/ch2.nii.gz" ] || [ ! -f "$templates/aal.nii.gz" ]; then
    echo "FAILED: $templates/ch2.nii.gz or aal.nii.gz is missing (install mricron-data; ./run does)"
    exit 1
  fi
}
