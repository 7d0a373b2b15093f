#!/usr/bin/env bash
# Tools/edge_offset.py on two phantoms of a labelled ball (radius 12 mm, 1 mm
# voxels, intensity 100 in a background of 50): alone, the gradient's peak is
# on the label's boundary (within 0.15 mm: smoothing a sphere by sigma = 1 mm
# moves the peak in by about sigma^2 / 2R = 0.04 mm, and the profile is
# sampled every 0.05 mm); with a brighter shell (200) from 13.5 to 15.5 mm,
# whose edge is four times as strong and 1.5 mm out, the peak follows that
# edge (median at least 1 mm out). A missing label and a missing file are
# refused, each named.
# Usage: TestEdgeOffset.sh TOOL
set -u
tool=$1
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
/usr/bin/python3 - "$work" <<'PY'
import sys
import nibabel, numpy
work = sys.argv[1]
z, y, x = numpy.mgrid[0:48, 0:48, 0:48]
r = numpy.sqrt((x - 23.5) ** 2 + (y - 23.5) ** 2 + (z - 23.5) ** 2)
labels = (r <= 12).astype(numpy.int16)
ball = numpy.where(labels > 0, 100.0, 50.0).astype(numpy.float32)
shell = numpy.where((r > 13.5) & (r <= 15.5), 200.0, ball).astype(numpy.float32)
affine = numpy.diag([-1.0, -1.0, 1.0, 1.0])
for name, data in [("labels", labels), ("ball", ball), ("shell", shell)]:
    nibabel.save(nibabel.Nifti1Image(data, affine), f"{work}/{name}.nii.gz")
PY
status=0
median() { echo "$1" | sed -n 's/.*median \([-+0-9.]*\) mm.*/\1/p'; }
out=$(/usr/bin/python3 "$tool" "$work/ball.nii.gz" "$work/labels.nii.gz" --label 1) || { echo "FAIL: ball"; exit 1; }
echo "ball: $out"
awk -v m="$(median "$out")" 'BEGIN { exit !(m >= -0.15 && m <= 0.15) }' || { echo "FAIL: the ball's peak is off its boundary"; status=1; }
out=$(/usr/bin/python3 "$tool" "$work/shell.nii.gz" "$work/labels.nii.gz" --label 1) || { echo "FAIL: shell"; exit 1; }
echo "shell: $out"
awk -v m="$(median "$out")" 'BEGIN { exit !(m >= 1.0) }' || { echo "FAIL: the shell's edge should draw the peak out"; status=1; }
if /usr/bin/python3 "$tool" "$work/ball.nii.gz" "$work/labels.nii.gz" --label 7 2>"$work/err"; then
  echo "FAIL: a label with no voxel was accepted"; status=1
fi
grep -q "no voxel has label 7" "$work/err" || { echo "FAIL: the missing label's error"; cat "$work/err"; status=1; }
if /usr/bin/python3 "$tool" "$work/none.nii.gz" "$work/labels.nii.gz" --label 1 2>"$work/err"; then
  echo "FAIL: a missing image was accepted"; status=1
fi
grep -q "none.nii.gz: cannot read it as an image" "$work/err" || { echo "FAIL: the missing image's error"; cat "$work/err"; status=1; }
exit $status
