#!/usr/bin/env bash
# DynSubSegment, the 3D Slicer CLI module, run the ways Slicer and nipype run it:
#  - `--xml` prints only the descriptor, which keeps Slicer's parser rules and
#    from which nipype's Slicer interface generator builds a working class;
#  - the Colin27 left caudate, the volume given as NRRD and each of the demo's
#    36 landmarks as one `--seed x,y,z` (LPS), as Slicer passes a markups
#    list: Dice >= 0.80 against AAL (the issue's bar; it measures 0.850), the
#    labelmap NRRD on the volume's grid, the model a .vtp marked SPACE=LPS,
#    and <filter-progress> rising to 1;
#  - one point only: read as a click inside the caudate;
#  - a markups file with several lists, or two atlas labels: segmented
#    together, with a .seg.nrrd that names them; a list of one point is a
#    click inside its structure (its start, or its atlas label's click);
#  - bad input: exit 1 with a message naming the problem and no output;
#    a usage error: exit 2.
# Needs MODULE (the executable), DATA and TOOLS; Debian's python3 with
# python3-nipype and python3-nibabel, and teem-apps (teem-unu).
set -u
source "$(dirname "${BASH_SOURCE[0]}")/../../dynsub/test/Checks.sh"
require_colin27
here=$(dirname "${BASH_SOURCE[0]}")
python=/usr/bin/python3
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

"$MODULE" --xml >"$work/xml.out" 2>"$work/xml.err"
check "--xml exits 0" test $? -eq 0
check "--xml prints nothing on stderr" test ! -s "$work/xml.err"
check "--xml starts with <?xml" test "$(head -c 5 "$work/xml.out")" = "<?xml"
check "descriptor: Slicer's rules, the program's flags, nipype's generator" \
  "$python" "$here/slicer_module_check.py" descriptor "$MODULE"

"$python" "$TOOLS/nifti_to_nrrd.py" "$templates/ch2.nii.gz" "$work/ch2.nrrd"
check "Colin27 written as NRRD" test -s "$work/ch2.nrrd"
mapfile -t seeds < <("$python" -c '
import json, sys
for p in json.load(open(sys.argv[1]))["markups"][0]["controlPoints"]:
    print("--seed"); print("%r,%r,%r" % tuple(p["position"]))' "$DATA/Landmarks/caudate_left.mrk.json")
check "36 landmarks as --seed arguments" test "${#seeds[@]}" -eq 72

"$MODULE" "${seeds[@]}" --labelmap "$work/caudate.nrrd" --model "$work/caudate.vtp" --report "$work/report.json" \
  --segmentation "$work/caudate.seg.nrrd" --labelValue 7 "$work/ch2.nrrd" >"$work/run.out" 2>"$work/run.err"
check "caudate: exit 0" test $? -eq 0
cat "$work/run.out" | grep -v filter-progress; cat "$work/run.err"
check "caudate: Dice >= 0.80, labelmap on the volume's grid with value 7" \
  "$python" "$here/slicer_module_check.py" dice "$work/caudate.nrrd" 7 "$templates/aal.nii.gz" 71 0.80
check "caudate: the .seg.nrrd holds the labelmap as one named segment" \
  "$python" "$here/slicer_module_check.py" segmentation "$work/caudate.seg.nrrd" "$work/caudate.nrrd" "structure=7"
check "caudate: the model is marked SPACE=LPS for Slicer" grep -q 'Name="SPACE"' "$work/caudate.vtp"
check "caudate: report written" grep -q '"landmark_count": 36' "$work/report.json"
check "caudate: progress rises to 1.00" awk -F'[<>]' '/<filter-progress>/ { if ($3 < last) bad = 1; last = $3; n++ }
  END { exit !(n >= 5 && !bad && last == 1.00) }' "$work/run.out"
check "caudate: stdout is tags and the summary only" test -z "$(grep -v -e '^<filter-' -e '^segmented ' "$work/run.out")"
check "caudate: the ends beyond the points are followed by default" grep -q '"slice_ends": true' "$work/report.json"

"$MODULE" "${seeds[@]}" --pointsReachEnds --labelmap "$work/ends.nrrd" --report "$work/ends.json" "$work/ch2.nrrd" \
  >"$work/ends.out" 2>&1
check "points reaching both ends: exit 0" test $? -eq 0
check "points reaching both ends: nothing followed beyond them" grep -q '"slice_ends": false' "$work/ends.json"

# The same points less their two outermost slices: the module says how far it
# followed the tissue past the slices left, and what to check if that is wrong.
mapfile -t inner < <("$python" -c '
import json, sys
points = [p["position"] for p in json.load(open(sys.argv[1]))["markups"][0]["controlPoints"]]
ys = sorted({round(p[1], 3) for p in points})
for p in points:
    if round(p[1], 3) not in (ys[0], ys[-1]): print("--seed"); print("%r,%r,%r" % tuple(p))' \
  "$DATA/Landmarks/caudate_left.mrk.json")
"$MODULE" "${inner[@]}" --maxLevel 0 --labelmap "$work/inner.nrrd" "$work/ch2.nrrd" >"$work/inner.out" 2>&1
check "points short of the ends: exit 0" test $? -eq 0
check "points short of the ends: says how far it followed the tissue, and what to check" \
  grep -q "<filter-comment>followed the structure's tissue past .* mm.*Points reach both ends" "$work/inner.out"

"$MODULE" --seed 15.4,-1.5,16.0 --labelmap "$work/inside.nrrd" --report "$work/inside.json" "$work/ch2.nrrd" \
  >"$work/inside.out" 2>&1
check "one point: exit 0" test $? -eq 0
check "one point: read as a click inside" grep -q '"springs": "boundary points"' "$work/inside.json"
# The flag's advice names the module's options, not dynsub segment's.
check "one point: flagged one_click, advising the module's own options" \
  grep -q -- "not to trust (one_click).*(--atlasLabel with --inside)" "$work/inside.out"
check "one point: no dynsub segment option in the advice" bash -c "! grep -q -- '--init' '$work/inside.out'"
check "one point: a caudate-sized region (Dice >= 0.5)" \
  "$python" "$here/slicer_module_check.py" dice "$work/inside.nrrd" 1 "$templates/aal.nii.gz" 71 0.5

# The atlas start by name, with the point inside: the run is checked, not
# its accuracy (Colin27 is the atlas's own brain).
"$MODULE" --atlasLabel 71 --inside 15.4,-1.5,16.0 --labelmap "$work/atlas.nrrd" --report "$work/atlas.json" \
  --segmentation "$work/atlas.seg.nrrd" "$work/ch2.nrrd" >"$work/atlas.out" 2>&1
check "atlas start: exit 0" test $? -eq 0
check "atlas start: the report has the registration" grep -q '"affine_iterations"' "$work/atlas.json"
check "atlas start: the segment is named by the atlas's table (71: Caudate_L)" \
  "$python" "$here/slicer_module_check.py" segmentation "$work/atlas.seg.nrrd" "$work/atlas.nrrd" "Caudate_L=1"

# expect_failure NAME CODE PATTERN ARGS...: exit CODE, PATTERN on stderr, no output file.
expect_failure() {
  local name=$1 code=$2 pattern=$3; shift 3
  rm -f "$work/bad.nrrd"
  "$MODULE" "$@" >"$work/bad.out" 2>"$work/bad.err"
  local status=$?
  check "$name: exit $code (got $status)" test "$status" -eq "$code"
  check "$name: says '$pattern'" grep -q -- "$pattern" "$work/bad.err"
  check "$name: no labelmap" test ! -e "$work/bad.nrrd"
  check "$name: no temporary file" test -z "$(ls -A "$work" | grep '^\.tmp')"
}
expect_failure "missing volume" 1 "no-such.nrrd" "${seeds[@]}" --labelmap "$work/bad.nrrd" "$work/no-such.nrrd"
expect_failure "three points" 2 "--seed: 3 landmarks are too few" --seed 1,2,3 --seed 4,5,6 --seed 7,8,9 \
  --labelmap "$work/bad.nrrd" "$work/ch2.nrrd"
expect_failure "no points" 2 "no landmarks to build the initial model from" --labelmap "$work/bad.nrrd" "$work/ch2.nrrd"
expect_failure "malformed point" 2 "expected x,y,z" --seed 1,2 --labelmap "$work/bad.nrrd" "$work/ch2.nrrd"
expect_failure "a word for the label value" 2 "labelValue: 'abc' is not a number" --labelValue abc --seed 1,2,3 \
  --labelmap "$work/bad.nrrd" "$work/ch2.nrrd"
expect_failure "a point with a coordinate missing" 2 "expected x,y,z" --seed 17.5,,21,21 --labelmap "$work/bad.nrrd" \
  "$work/ch2.nrrd"
expect_failure "a point with its first coordinate missing" 2 "expected x,y,z" --seed ,17.5,21,21 \
  --labelmap "$work/bad.nrrd" "$work/ch2.nrrd"
expect_failure "NaN point" 2 "expected x,y,z" --seed nan,2,3 --labelmap "$work/bad.nrrd" "$work/ch2.nrrd"
expect_failure "point outside the volume" 1 "outside the image" --seed 500,0,0 "${seeds[@]:2}" \
  --labelmap "$work/bad.nrrd" "$work/ch2.nrrd"
expect_failure "no output asked for" 2 "nothing to write" "${seeds[@]}" "$work/ch2.nrrd"
expect_failure "unknown labelmap format" 2 "unknown labelmap format" "${seeds[@]}" --labelmap "$work/bad.png" \
  "$work/ch2.nrrd"
# "x.gz" is no compressed NIfTI name: refused before the run, as every output name is.
expect_failure "a labelmap named .gz alone" 2 "unknown labelmap format '.gz'" "${seeds[@]}" \
  --labelmap "$work/bad.gz" "$work/ch2.nrrd"
expect_failure "--xml with other arguments" 2 "takes no other argument" --xml "${seeds[@]}" \
  --labelmap "$work/bad.nrrd" "$work/ch2.nrrd"
cp "$work/ch2.nrrd" "$work/input_copy.nrrd"
expect_failure "the labelmap written over the input volume" 2 "is an input of this run too" "${seeds[@]}" \
  --labelmap "$work/input_copy.nrrd" "$work/input_copy.nrrd"
check "the input volume is left as it was" cmp -s "$work/ch2.nrrd" "$work/input_copy.nrrd"
expect_failure "an atlas label list ending in ';'" 2 "an empty structure between ';'" --atlasLabel "Caudate_L;" \
  --labelmap "$work/bad.nrrd" "$work/ch2.nrrd"
expect_failure "model in a missing directory" 1 "no-dir" "${seeds[@]}" --labelmap "$work/bad.nrrd" \
  --model "$work/no-dir/m.vtp" "$work/ch2.nrrd"
mkdir "$work/folder.vtp"
expect_failure "a model named like a folder that exists" 1 "folder.vtp: is a directory" "${seeds[@]}" \
  --labelmap "$work/bad.nrrd" --model "$work/folder.vtp" "$work/ch2.nrrd"
# Three structures' point lists in one markups file, as Slicer keeps them,
# the third a single point: segmented together, each a barrier to the
# others, into one labelmap (values from --labelValue up), one model and one
# .seg.nrrd naming them. The single point is a click inside its structure (as
# one point is for one structure), here the left thalamus (the voxel nearest
# the centroid of AAL's label 77). Dice bars as for one structure for the
# lists (0.80; they measure 0.853 and 0.890): Colin27 is the brain the
# defaults were tuned on, so this checks the run, not accuracy. One click
# alone measures 0.52 on this brain; its bar, 0.4, checks that the thalamus
# grew from the click, which a point read as a boundary point would not (it
# is refused).
"$python" - "$DATA/Landmarks" "$work/lists.mrk.json" <<'PY'
import json, sys
lists = []
for name, file in (("Caudate L", "caudate_left"), ("Putamen L", "putamen_left")):
    markup = json.load(open(f"{sys.argv[1]}/{file}.mrk.json"))["markups"][0]
    markup["name"] = name
    lists.append(markup)
lists.append({"type": "Fiducial", "coordinateSystem": "LPS", "name": "Thalamus L",
              "controlPoints": [{"label": "inside", "position": [12.0, 18.0, 8.0]}]})
json.dump({"markups": lists}, open(sys.argv[2], "w"))
PY
"$MODULE" --landmarks "$work/lists.mrk.json" --labelValue 5 --labelmap "$work/lists.nrrd" --model "$work/lists.vtp" \
  --segmentation "$work/lists.seg.nrrd" --report "$work/lists.json" "$work/ch2.nrrd" >"$work/lists.out" 2>"$work/lists.err"
check "three point lists: exit 0" test $? -eq 0
grep -v filter- "$work/lists.out"; cat "$work/lists.err"
for structure in "caudate 5 71 0.80" "putamen 6 73 0.80" "thalamus 7 77 0.4"; do
  read -r name value reference minimum <<<"$structure"
  check "three point lists: the $name ($value) has Dice >= $minimum" \
    "$python" "$here/slicer_module_check.py" dice "$work/lists.nrrd" "$value" "$templates/aal.nii.gz" "$reference" \
    "$minimum"
done
check "three point lists: the one point is the thalamus's start" \
  grep -q '"init": "inside:the one point of Thalamus_L"' "$work/lists.json"
check "three point lists: the .seg.nrrd names them, and holds the labelmap's voxels" \
  "$python" "$here/slicer_module_check.py" segmentation "$work/lists.seg.nrrd" "$work/lists.nrrd" \
  "Caudate L=5" "Putamen L=6" "Thalamus L=7"
check "three point lists: one model, its points labelled by structure" grep -q 'Name="label"' "$work/lists.vtp"
check "three point lists: the run's report lists them" grep -q '"name": "Putamen_L"' "$work/lists.json"
# Lists of one point each, paired with atlas labels: each point is the click
# inside its atlas structure (--inside), which the run's report keeps.
"$python" - "$work/clicks.mrk.json" <<'PY'
import json, sys
lists = [{"type": "Fiducial", "coordinateSystem": "LPS", "name": name,
          "controlPoints": [{"label": "inside", "position": position}]}
         for name, position in (("Caudate L", [15.4, -1.5, 16.0]), ("Putamen L", [25.0, -2.0, 2.0]))]
json.dump({"markups": lists}, open(sys.argv[1], "w"))
PY
"$MODULE" --landmarks "$work/clicks.mrk.json" --atlasLabel "Caudate_L;73" --labelmap "$work/clicks.nrrd" \
  --report "$work/clicks.json" "$work/ch2.nrrd" >"$work/clicks.out" 2>"$work/clicks.err"
check "lists of one point with atlas labels: exit 0" test $? -eq 0
check "lists of one point with atlas labels: each structure's click inside is in the report" \
  test "$(grep -c '"inside_lps_mm"' "$work/clicks.json")" -eq 2
# Two atlas labels, separated by ';': segmented together, named by the
# atlas's table. Colin27 is the atlas's own brain, so this checks the run and
# its outputs, not accuracy.
"$MODULE" --atlasLabel "Caudate_L;73" --labelmap "$work/atlas2.nrrd" --segmentation "$work/atlas2.seg.nrrd" \
  "$work/ch2.nrrd" >"$work/atlas2.out" 2>"$work/atlas2.err"
check "two atlas labels: exit 0" test $? -eq 0
grep -v filter- "$work/atlas2.out"; cat "$work/atlas2.err"
check "two atlas labels: the .seg.nrrd names them by the atlas's table, and holds the labelmap's voxels" \
  "$python" "$here/slicer_module_check.py" segmentation "$work/atlas2.seg.nrrd" "$work/atlas2.nrrd" \
  "Caudate_L=1" "Putamen_L=2"
expect_failure "three point lists, one atlas label" 2 "give one atlas label per list" \
  --landmarks "$work/lists.mrk.json" --atlasLabel Caudate_L --labelmap "$work/bad.nrrd" "$work/ch2.nrrd"
expect_failure "point lists and --seed" 2 "add boundary points to the lists of a points file, not as --seed" \
  --landmarks "$work/lists.mrk.json" "${seeds[@]}" --labelmap "$work/bad.nrrd" "$work/ch2.nrrd"
expect_failure "point lists past label 255" 2 "pass 255" \
  --landmarks "$work/lists.mrk.json" --labelValue 255 --labelmap "$work/bad.nrrd" "$work/ch2.nrrd"
expect_failure "a segmentation not .seg.nrrd" 2 "written as .seg.nrrd" "${seeds[@]}" --labelmap "$work/bad.nrrd" \
  --segmentation "$work/bad-seg.nrrd" "$work/ch2.nrrd"
expect_failure "sigma out of range" 2 "sigma" "${seeds[@]}" --sigma 50 --labelmap "$work/bad.nrrd" "$work/ch2.nrrd"
expect_failure "unknown option" 2 "frobnicate" --frobnicate "$work/ch2.nrrd"
expect_failure "a misspelt option" 2 "did you mean '--sigma'" --sigm 2 "$work/ch2.nrrd"

mkdir "$work/nipype"
check "nipype's generated interface runs the module" \
  "$python" "$here/slicer_module_check.py" nipype-run "$MODULE" "$work/ch2.nrrd" \
  "$DATA/Landmarks/caudate_left.mrk.json" "$work/nipype"

echo "$failures failure(s)"
exit $((failures > 0))
