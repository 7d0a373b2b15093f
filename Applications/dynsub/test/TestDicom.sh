#!/usr/bin/env bash
# Reading DICOM series: a ball phantom on an oblique, anisotropic grid, written
# as an MR series by DCMTK's dump2dcm (Tools/dicom_phantom.py; a writer DynSub
# does not use) and as NIfTI, is segmented from both:
#  - from the series: Dice >= 0.95 and mean surface distance <= 0.375 mm (half
#    the smallest voxel side) against the analytic ball, and the --reference
#    labelmap (NIfTI) is accepted as being on the series' grid;
#  - from the NIfTI: the same labelmap, to within 0.5 % of the ball's voxels
#    (the NIfTI stores the axes as 32-bit floats, DICOM as decimals, so a few
#    boundary voxels may fall the other way); and the NIfTI is read without
#    opening GDCM's libraries or DynSub's DICOM library (the loader's record).
# One slice's file is refused as 2D, one cut short as truncated.
# And a broken series gets a clear error, exit code 1 and no output (not the
# abort Debian's GDCM gives for some): a truncated slice (in its header, in a
# sequence of undefined length, after its meta header, in its pixels), a
# missing slice, a slice without its position or of another orientation, two
# slices at one position, two series, no series. Needs DYNSUB, TOOLS and dump2dcm/dcmodify (Debian package dcmtk).
set -u
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
source "$(dirname "${BASH_SOURCE[0]}")/Checks.sh"
expect_error() {
  local name=$1 fragment=$2 output=$3; shift 3
  "$@" >"$work/stdout" 2>"$work/stderr"
  local rc=$?
  check "$name: exit code 1 (got $rc)" test "$rc" -eq 1
  check "$name: message mentions '$fragment'" grep -q -- "$fragment" "$work/stderr"
  check "$name: no output" test ! -e "$output"
}

python3 "$TOOLS/dicom_phantom.py" "$work/phantom" >/dev/null
check "the phantom series has 32 slices" test "$(ls "$work/phantom/series" | wc -l)" -eq 32

"$DYNSUB" segment "$work/phantom/series" --landmarks "$work/phantom/ball.csv" --reference "$work/phantom/ball.nii.gz" \
  --reference-label 1 --no-figures --out "$work/dicom" >"$work/dicom.log" 2>&1
check "segment reads the DICOM series" test $? -eq 0
cat "$work/dicom.log"
dice=$(sed -n 's/^  "dice": \([-0-9.e+]*\),$/\1/p' "$work/dicom/report.json")
distance=$(sed -n 's/^  "mean_surface_distance_mm": \([-0-9.e+]*\),$/\1/p' "$work/dicom/report.json")
check "DICOM: Dice $dice >= 0.95" awk -v d="$dice" 'BEGIN { exit !(d != "" && d >= 0.95) }'
check "DICOM: mean surface distance $distance <= 0.375 mm" awk -v d="$distance" 'BEGIN { exit !(d != "" && d <= 0.375) }'

"$DYNSUB" segment "$work/phantom/phantom.nii.gz" \
  --landmarks "$work/phantom/ball.csv" --no-figures --out "$work/nifti" >/dev/null 2>&1
check "segment reads the same phantom as NIfTI" test $? -eq 0
check "the DICOM and NIfTI labelmaps agree" python3 - "$work/dicom/labelmap.nii.gz" "$work/nifti/labelmap.nii.gz" <<'PY'
import gzip, struct, sys
def read(path):
    data = gzip.open(path).read()
    offset = int(struct.unpack_from("<f", data, 108)[0])
    return struct.unpack_from("<4h", data, 40), struct.unpack_from("<3f", data, 80), data[offset:]
(dims_a, spacing_a, a), (dims_b, spacing_b, b) = read(sys.argv[1]), read(sys.argv[2])
differ = sum(x != y for x, y in zip(a, b))
inside = sum(1 for x in a if x)
print(f"{differ} of {inside} labelled voxels differ")
sys.exit(0 if dims_a == dims_b and spacing_a == spacing_b and len(a) == len(b) and differ <= 0.005 * inside else 1)
PY

broken() {  # broken NAME: a copy of the series to break
  cp -r "$work/phantom/series" "$work/$1"
}
rejects() {  # rejects NAME FRAGMENT DIR: segment on $work/DIR fails with FRAGMENT and writes nothing
  expect_error "$1" "$2" "$work/out_$3" \
    "$DYNSUB" segment "$work/$3" --landmarks "$work/phantom/ball.csv" --out "$work/out_$3"
}
cut() {  # cut NAME SLICE BYTES: a copy of the series with one slice cut to its first BYTES
  broken "$1"
  head -c "$3" "$work/phantom/series/$2" >"$work/$1/$2"
}
cut header slice_007.dcm 700
rejects "a slice cut short in its header" "slice_007.dcm: a truncated DICOM file" header
cut sequence slice_007.dcm 460
rejects "a slice cut short in a sequence of undefined length" "slice_007.dcm: a truncated DICOM file" sequence
cut metaonly slice_007.dcm 320
rejects "a slice of nothing but its meta header" "nothing follows the meta header" metaonly
cut pixels slice_010.dcm 2000
rejects "a slice cut short in its pixels" "slice_010.dcm: a truncated DICOM file: element (7fe0,0010)" pixels
broken gap
rm "$work/gap/slice_012.dcm"
rejects "a missing slice" "not evenly spaced" gap
broken two
dcmodify -nb -m "(0020,000e)=1.2.826.0.1.3680043.10.1347.9" "$work/two/slice_005.dcm"
rejects "two series" "holds 2 DICOM series" two
# A slice ITK would place by guesswork or read in another's geometry.
broken noposition
dcmodify -nb -e "(0020,0032)" "$work/noposition/slice_009.dcm"
rejects "a slice without its position" "slice_009.dcm: a slice of the DICOM series states no Image Position" noposition
broken tilted
dcmodify -nb -m "(0020,0037)=1\\0\\0\\0\\0.9\\0.43589" "$work/tilted/slice_009.dcm"
rejects "a slice of another orientation" "slice_009.dcm: a slice of the DICOM series has another Image Orientation" tilted
broken twice
cp "$work/twice/slice_009.dcm" "$work/twice/slice_009b.dcm"
dcmodify -nb -m "(0008,0018)=1.2.826.0.1.3680043.10.1347.99" "$work/twice/slice_009b.dcm"
rejects "two slices at one position" "two slices of the DICOM series lie at one position" twice
check "two slices at one position: GDCM's own notice is not printed" \
  bash -c "! grep -q 'not unique' '$work/stderr'"
# One file of the series: read (by GDCM) and refused as the 2D image it is,
# naming the series' folder to give instead.
expect_error "one slice file" \
  "slice_007.dcm: not a 3D image (1 voxel(s) along axis 2): a DICOM file holds one slice of its series; give the series' folder ($work/phantom/series)" \
  "$work/out_one" \
  "$DYNSUB" segment "$work/phantom/series/slice_007.dcm" --landmarks "$work/phantom/ball.csv" --out "$work/out_one"
# One file cut short is walked before GDCM sees it, as a series's files are.
expect_error "one file cut short in its header" "slice_007.dcm: a truncated DICOM file" "$work/out_cut" \
  "$DYNSUB" segment "$work/header/slice_007.dcm" --landmarks "$work/phantom/ball.csv" --out "$work/out_cut"
mkdir "$work/none"
echo "not an image" >"$work/none/README.txt"
rejects "no series" "holds no DICOM series" none

echo "$failures failure(s)"
test "$failures" -eq 0
