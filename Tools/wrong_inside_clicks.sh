#!/usr/bin/env bash
# Clicks inside (--inside) with an atlas start, right and wrong, on
# single-scan subjects made from Colin27 (`dynsub subject`, SEEDS, SNR 20-30):
# for the left caudate, putamen, thalamus and hippocampus, the structure's
# deepest voxel (right), that voxel read in the other convention (x and y
# negated), mirrored left-right (x negated), and the deepest voxel of a
# neighbouring structure (the caudate's putamen, the putamen's pallidum, the
# thalamus's caudate, the hippocampus's amygdala). Prints, per run, the Dice
# against the subject's own label, how far the click moved the atlas's
# structure (report.json's trust.inside_shift_mm) and the trust flags.
# SETTINGS are the generator's (`dynsub subject --set`, one per word; the
# thick-slice test subjects: SEEDS="301 302 303 304" SETTINGS="snr=20,30
# thick_fraction=1").
# Usage: [SEEDS="101 102"] [SETTINGS=...] [DYNSUB=BINARY] Tools/wrong_inside_clicks.sh [WORKDIR]
# (from the repository; build first; needs python3-nibabel and python3-scipy)
set -eu
root=$(cd "$(dirname "$0")/.." && pwd)
dynsub=${DYNSUB:-$root/build/bin/dynsub}
templates=/usr/share/mricron/templates
work=${1:-$(mktemp -d)}
mkdir -p "$work"
sets=()
for setting in ${SETTINGS:-snr=20,30}; do sets+=(--set "$setting"); done
negate() { awk -v v="$1" 'BEGIN { print -v }'; }
for seed in ${SEEDS:-101 102 103 104}; do
  subject=$work/s$seed
  [ -f "$subject/image.nii.gz" ] ||
    "$dynsub" subject "$templates/ch2.nii.gz" "$templates/aal.nii.gz" --seed "$seed" "${sets[@]}" \
      --out "$subject" >/dev/null
  for pair in "71 73 Caudate_L" "73 75 Putamen_L" "77 71 Thalamus_L" "37 41 Hippocampus_L"; do
    set -- $pair
    read -r own other < <(/usr/bin/python3 - "$subject/labels.nii.gz" "$1" "$2" <<'PY'
import sys
import nibabel
import numpy
from scipy import ndimage
image = nibabel.load(sys.argv[1])
labels = numpy.asarray(image.dataobj)
def deepest(value):  # the voxel deepest inside the label, LPS mm
    depth = ndimage.distance_transform_edt(labels == value)
    ras = image.affine @ numpy.array([*numpy.unravel_index(numpy.argmax(depth), depth.shape), 1.0])
    return "%.1f,%.1f,%.1f" % (-ras[0], -ras[1], ras[2])
print(deepest(int(sys.argv[2])), deepest(int(sys.argv[3])))
PY
    )
    IFS=, read -r x y z <<<"$own"
    for kind in right convention mirror neighbour; do
      case $kind in
        right) click=$own ;;
        convention) click="$(negate "$x"),$(negate "$y"),$z" ;;
        mirror) click="$(negate "$x"),$y,$z" ;;
        neighbour) click=$other ;;
      esac
      out=$work/run_${seed}_$3_$kind
      if "$dynsub" segment "$subject/image.nii.gz" --init atlas --atlas-label "$3" --inside="$click" \
        --no-figures --out "$out" >"$out.log" 2>&1; then
        # Dice on the image's grid, the label read at each voxel's centre (the
        # labels are on the fine grid, the image may have thick slices).
        /usr/bin/python3 - "$out" "$subject/labels.nii.gz" "$1" "s$seed $3 $kind" <<'PY'
import json
import sys
import nibabel
import numpy
from scipy import ndimage
out, labels_path, value, name = sys.argv[1], sys.argv[2], int(sys.argv[3]), sys.argv[4]
result = nibabel.load(out + "/labelmap.nii.gz")
labels = nibabel.load(labels_path)
inside = numpy.asarray(result.dataobj) > 0
to_fine = numpy.linalg.inv(labels.affine) @ result.affine
grid = numpy.indices(inside.shape).reshape(3, -1)
at = to_fine[:3, :3] @ grid + to_fine[:3, 3:]
truth = ndimage.map_coordinates(numpy.asarray(labels.dataobj), at, order=0).reshape(inside.shape) == value
dice = 2 * (inside & truth).sum() / (inside.sum() + truth.sum())
trust = json.load(open(out + "/report.json"))["trust"]
print("%s: Dice %.3f, moved %.1f mm, flags %s" % (name, dice, trust.get("inside_shift_mm", 0),
      ",".join(f["name"] for f in trust.get("flags", [])) or "-"))
PY
      else
        echo "s$seed $3 $kind: failed: $(tail -1 "$out.log")"
      fi
    done
  done
done
