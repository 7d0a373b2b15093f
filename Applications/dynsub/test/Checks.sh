# Sourced by the command-line test scripts: one named check at a time, failures counted.
# A failed check returns 1, so that `check ... || show-the-log` shows why.
failures=0
check() {  # check NAME CONDITION...
  local name=$1; shift
  if "$@"; then echo "ok: $name"; else echo "FAILED: $name"; failures=$((failures + 1)); return 1; fi
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
