#!/usr/bin/env bash
# Runs the demo's commands with two builds and compares every output file,
# for changes that must not change behaviour (a refactoring, a move):
#
#   Tools/compare_demo.sh OLD_BIN_DIR NEW_BIN_DIR [WORK_DIR]
#
# The commands are those of `./run demo` (limit, fit, deform, segment, solid
# sculpt) plus `solid stats` and `render`. Files must be byte-identical; a
# report.json may differ only in its timings (seconds, stage seconds); a PNG,
# .vtp, .vtu or .nii.gz whose bytes differ is compared by its contents (pixels,
# arrays, header fields and voxels) with NEW_BIN_DIR/SameContents when it is
# there, and named "same contents" when they agree (their compression may
# differ between builds). Needs an X
# display or xvfb-run for the figures. Exits 1 when anything differs.
set -euo pipefail
if [ $# -lt 2 ]; then
  sed -n '2,9p' "$0"
  exit 2
fi
old=$(cd "$1" && pwd)
new=$(cd "$2" && pwd)
work=${3:-$(mktemp -d)}
data=$(cd "$(dirname "$0")/../Data" && pwd)
mri=/usr/share/mricron/templates

with_display() {
  if [ -n "${DISPLAY:-}" ]; then "$@"; else xvfb-run -a -s "-screen 0 1280x1024x24 -noreset" "$@"; fi
}

run_demo() {
  local bin=$1 out=$2
  rm -rf "$out"
  mkdir -p "$out"
  "$bin/dynsub" limit "$data/Meshes/cube.obj" --samples-per-face 8 --out "$out/cube_limit.vtp" >/dev/null
  with_display "$bin/dynsub" fit "$data/PointClouds/torus.xyz" --init torus --out "$out/torus_fit" >/dev/null
  "$bin/dynsub" deform "$data/Meshes/sheet.obj" --springs "$data/Deform/sheet_hat.springs" --fix-boundary \
    --out "$out/sheet_hat" >/dev/null
  with_display "$bin/dynsub" segment "$mri/ch2.nii.gz" --landmarks "$data/Landmarks/caudate_left.mrk.json" \
    --reference "$mri/aal.nii.gz" --reference-label 71 --out "$out/caudate_left" >/dev/null
  with_display "$bin/dynsub" solid sculpt "$data/Solids/cube3.lattice" --script "$data/Solids/arm.sculpt" \
    --out "$out/sculpted_arm" >/dev/null
  "$bin/dynsub" solid stats "$data/Solids/cube3.lattice" --level 1 >"$out/stats.json"
  with_display "$bin/dynsub" render --surface "$out/caudate_left/surface.vtp" \
    --convergence "$out/caudate_left/convergence.csv" --image "$mri/ch2.nii.gz" \
    --landmarks "$data/Landmarks/caudate_left.mrk.json" --out "$out/render" >/dev/null
}

run_demo "$old" "$work/old"
run_demo "$new" "$work/new"

timings='"seconds"|"crop"|"edge_potential"|"evolution"|"voxelize"'
differ=0
count=0
while IFS= read -r file; do
  count=$((count + 1))
  if [[ $file == *report.json ]]; then
    if ! diff <(grep -Ev "$timings" "$work/old/$file") <(grep -Ev "$timings" "$work/new/$file") >/dev/null; then
      echo "differs: $file"
      differ=1
    fi
  elif ! cmp -s "$work/old/$file" "$work/new/$file"; then
    if [[ $file == *.png || $file == *.vtp || $file == *.vtu || $file == *.nii.gz ]] && [ -x "$new/SameContents" ] &&
      "$new/SameContents" "$work/old/$file" "$work/new/$file" >/dev/null; then
      echo "same contents, other bytes: $file"
    else
      echo "differs: $file"
      differ=1
    fi
  fi
done < <(cd "$work/old" && find . -type f | sort)
if [ "$(cd "$work/old" && find . -type f | wc -l)" != "$(cd "$work/new" && find . -type f | wc -l)" ]; then
  echo "the two runs wrote different sets of files"
  differ=1
fi
echo "$count files compared in $work: $([ $differ = 0 ] && echo 'all equal (report.json but for timings; figures, surfaces and labelmaps by contents where their bytes differ)' || echo 'some differ')"
exit $differ
