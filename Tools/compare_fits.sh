#!/usr/bin/env bash
# Side-by-side timing of two dynsub executables on CGAL's scans (the bear,
# the kitten with Data/Meshes/kitten_genus1.obj, the eight with
# Data/Meshes/eight_genus2.obj; Debian package libcgal-demo), each case run
# by the first executable and then by the second, so that both see the same
# machine load:
#   Tools/compare_fits.sh OLD_DYNSUB NEW_DYNSUB [FIT OPTIONS...]
# Prints per run: scan, executable, wall time, peak memory, steps, max error %.
set -euo pipefail
if [ $# -lt 2 ]; then
  echo "usage: $0 OLD_DYNSUB NEW_DYNSUB [FIT OPTIONS...]" >&2
  exit 2
fi
old=$1 new=$2; shift 2
here=$(cd "$(dirname "$0")/.." && pwd)
archive=/usr/share/doc/libcgal-dev/data.tar.gz
[ -f "$archive" ] || { echo "$archive is missing (install libcgal-demo)" >&2; exit 1; }
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
tar xzf "$archive" -C "$work" data/meshes/bear.off data/points_3/kitten.xyz data/meshes/eight.off
value() { sed -n "s/^  \"$2\": \([-0-9.e+]*\),\{0,1\}$/\1/p" "$1"; }
run() {  # run NAME DYNSUB INPUT [OPTIONS...]
  local name=$1 dynsub=$2; shift 2
  local out="$work/out"
  rm -rf "$out"
  /usr/bin/time -f "%e %M" -o "$work/time" "$dynsub" fit "$@" --out "$out" >/dev/null 2>"$work/log" ||
    { echo "$name $dynsub FAILED: $(tail -1 "$work/log")"; return; }
  read -r seconds kb <"$work/time"
  echo "$name $dynsub ${seconds} s $((kb / 1024)) MB steps $(value "$out/report.json" iterations)" \
    "max_error_percent $(value "$out/report.json" max_error_percent)"
}
for dynsub in "$old" "$new"; do run eight "$dynsub" "$work/data/meshes/eight.off" --init "$here/Data/Meshes/eight_genus2.obj" "$@"; done
for dynsub in "$old" "$new"; do run kitten "$dynsub" "$work/data/points_3/kitten.xyz" --init "$here/Data/Meshes/kitten_genus1.obj" "$@"; done
for dynsub in "$old" "$new"; do run bear "$dynsub" "$work/data/meshes/bear.off" "$@"; done
