#!/usr/bin/env bash
# Segmenting the Colin27 MRI (Debian package mricron-data) against the expert
# AAL atlas drawn on the same brain, with default parameters:
#  - the left caudate from the demo's 36 landmarks (the structure the
#    defaults were tuned on);
#  - the cerebellum from 30 landmarks on 5 sagittal slices (looked at, with
#    others, when the edge thresholds were chosen), and the left thalamus
#    (not tuned on) and left putamen from 36 on 6 coronal slices.
# Each must reach Dice >= 0.85 (the issue's bar). Landmarks not in Data/ are
# made the same way as those in Data/ (Tools/landmarks_from_labels.py).
# The cerebellum from 15 landmarks (3 on each of 5 sagittal slices, made after
# the edge thresholds were chosen) must reach the bar too; it measures 0.866.
# Below the bar, a guard: the cerebellum from 12 landmarks on 4 sagittal slices
# measures 0.827 with the edge thresholds set by the landmarks and 0.751 with
# the image's percentile (Documentation/Segmentation.md); it must stay >= 0.80.
# Held out, at the bar: each cerebellar hemisphere from 30 points.
# Needs DYNSUB (the executable), DATA and TOOLS.
set -u
source "$(dirname "${BASH_SOURCE[0]}")/Checks.sh"
require_colin27
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

# segment_structure NAME LANDMARKS LABEL... (Dice bar: $bar)
bar=0.85
segment_structure() {
  local name=$1 landmarks=$2; shift 2
  "$DYNSUB" segment "$templates/ch2.nii.gz" --landmarks "$landmarks" --reference "$templates/aal.nii.gz" \
    --reference-label "$@" --out "$work/$name" >"$work/$name.log" 2>&1
  check "$name: segment succeeds" test $? -eq 0
  cat "$work/$name.log"
  local dice
  dice=$(sed -n 's/^  "dice": \([-0-9.e+]*\),$/\1/p' "$work/$name/report.json" 2>/dev/null)
  check "$name: Dice $dice >= $bar" awk -v d="$dice" -v bar="$bar" 'BEGIN { exit !(d != "" && d >= bar) }'
}

segment_structure caudate_left "$DATA/Landmarks/caudate_left.mrk.json" 71

# The labelmap must sit where the MRI does in any viewer: read without ITK,
# its dimensions, voxel sizes and sform equal the MRI's, and its qform (which
# ITK-SNAP and 3D Slicer prefer when set) is the same transform.
check "caudate_left: labelmap header places it on the MRI's grid" python3 - "$templates/ch2.nii.gz" \
  "$work/caudate_left/labelmap.nii.gz" <<'PY'
import gzip, math, struct, sys
def header(path):
    h = gzip.open(path).read()[:348]
    quatern = struct.unpack_from("<6f", h, 256)
    b, c, d = quatern[:3]
    a = math.sqrt(max(0.0, 1 - b * b - c * c - d * d))
    rotation = [[a*a+b*b-c*c-d*d, 2*(b*c-a*d), 2*(b*d+a*c)], [2*(b*c+a*d), a*a+c*c-b*b-d*d, 2*(c*d-a*b)],
                [2*(b*d-a*c), 2*(c*d+a*b), a*a+d*d-c*c-b*b]]
    pixdim = struct.unpack_from("<8f", h, 76)
    qfac = -1.0 if pixdim[0] < 0 else 1.0
    qform = [rotation[r][0] * pixdim[1] for r in range(3)], [rotation[r][1] * pixdim[2] for r in range(3)], \
            [rotation[r][2] * pixdim[3] * qfac for r in range(3)]
    qmatrix = [[qform[col][r] for col in range(3)] + [quatern[3 + r]] for r in range(3)]
    sform = struct.unpack_from("<12f", h, 280)
    return (struct.unpack_from("<4h", h, 40), pixdim[1:4], struct.unpack_from("<h", h, 252)[0],
            [list(sform[4 * r:4 * r + 4]) for r in range(3)], qmatrix)
mri, labels = header(sys.argv[1]), header(sys.argv[2])
close = lambda m, n: all(abs(x - y) < 1e-4 for r, s in zip(m, n) for x, y in zip(r, s))
ok = mri[0] == labels[0] and mri[1] == labels[1] and close(mri[3], labels[3])
ok = ok and (labels[2] == 0 or close(labels[4], mri[3]))
sys.exit(0 if ok else 1)
PY
# How far to trust it, in the report and on the surface: every landmark's
# edge distance, the share held by edges, and the per-point edge distance as
# surface.vtp point data (its name appears in the XML header).
check "caudate_left: report and surface say where edges hold it" python3 - "$work/caudate_left" <<'PY'
import json, sys
r = json.load(open(sys.argv[1] + "/report.json"))
ok = 0 < r["surface_on_edges"] <= 1 and all("edge_distance_mm" in l for l in r["landmark_residuals"])
ok = ok and isinstance(r["warnings"], list) and r["surface_volume_mm3"] > r["initial_volume_mm3"]
# The demo's clicks reach the caudate's ends: the result holds 1.28 times
# what their slices outline and is trusted (a result under 0.7 would be flagged).
t = r["trust"]
ok = ok and t["trusted"] and t["flags"] == [] and 1.0 < t["volume_ratio"] < 1.6
head = open(sys.argv[1] + "/surface.vtp", "rb").read(4096)
sys.exit(0 if ok and b'Name="edge_distance_mm"' in head else 1)
PY
segment_structure cerebellum "$DATA/Landmarks/cerebellum.mrk.json" $(seq 91 116)
# segment_from_atlas_points NAME VIEW SLICES POINTS LABEL...: landmarks made
# from the AAL labels' boundary (as Data/Landmarks/README.md says), then segment.
segment_from_atlas_points() {
  local name=$1 view=$2 slices=$3 points=$4; shift 4
  local labels
  labels=$(IFS=,; echo "$*")
  python3 "$TOOLS/landmarks_from_labels.py" "$templates/aal.nii.gz" "$labels" "$view" "$slices" "$points" \
    "$work/$name.mrk.json" >/dev/null
  segment_structure "$name" "$work/$name.mrk.json" "$@"
}
segment_from_atlas_points thalamus_left coronal 6 6 77
segment_from_atlas_points putamen_left coronal 6 6 73
segment_from_atlas_points cerebellum_15_points sagittal 5 3 $(seq 91 116)
bar=0.80 segment_from_atlas_points cerebellum_12_points sagittal 4 3 $(seq 91 116)
# Held out (first run after every choice was made): each cerebellar hemisphere
# from 30 points on 5 sagittal slices; they measure 0.870 (left) and 0.879.
segment_from_atlas_points cerebellum_left_hemisphere sagittal 5 6 $(seq 91 2 107)
segment_from_atlas_points cerebellum_right_hemisphere sagittal 5 6 $(seq 92 2 108)

# One click inside the left caudate (the demo landmarks' centroid) and no
# landmarks: the surface starts from the region grown from the click. It
# measures 0.643; the floor (0.58) guards against a return to the collapse
# every single click used to end in (Dice 0.000). Not the issue's bar (0.75).
"$DYNSUB" segment "$templates/ch2.nii.gz" --init seed:15.4,-1.5,16.0 --reference "$templates/aal.nii.gz" \
  --reference-label 71 --no-figures --out "$work/caudate_seed" >"$work/caudate_seed.log" 2>&1
check "caudate from one seed click: segment succeeds" test $? -eq 0
cat "$work/caudate_seed.log"
check "caudate from one seed click: Dice >= 0.58, the seed's region reported" python3 - "$work/caudate_seed" <<'PY'
import json, sys
r = json.load(open(sys.argv[1] + "/report.json"))
print("Dice", r["dice"], "seed", r["seed"])
ok = r["dice"] >= 0.58 and r["seed"]["springs"] == "boundary points" and not r["seed"]["leaked"]
# One click and nothing else is never to be trusted on its own.
ok = ok and not r["trust"]["trusted"] and [f["name"] for f in r["trust"]["flags"]] == ["one_click"]
sys.exit(0 if ok and r["seed"]["region_volume_mm3"] > 1000 and r["landmark_count"] == 0 else 1)
PY
# Four of the demo's clicks, two on each of two slices, outline no volume:
# the surface collapses (Dice 0.007), and the report must not call it trusted.
python3 - "$DATA/Landmarks/caudate_left.mrk.json" "$work/four.mrk.json" <<'PY'
import json, sys
document = json.load(open(sys.argv[1]))
points = document["markups"][0]["controlPoints"]
slices = sorted({round(p["position"][1], 1) for p in points})
chosen = [p for s in (slices[1], slices[-2]) for p in [q for q in points if round(q["position"][1], 1) == s][:2]]
document["markups"][0]["controlPoints"] = chosen
json.dump(document, open(sys.argv[2], "w"))
PY
"$DYNSUB" segment "$templates/ch2.nii.gz" --landmarks "$work/four.mrk.json" --no-figures --out "$work/four" \
  >"$work/four.log" 2>&1
check "four clicks: segment succeeds" test $? -eq 0
check "four clicks: the collapse is flagged" python3 - "$work/four" <<'PY'
import json, sys
trust = json.load(open(sys.argv[1] + "/report.json"))["trust"]
print(trust)
sys.exit(0 if not trust["trusted"] and "collapsed" in [f["name"] for f in trust["flags"]]
         and trust["initial_volume_ratio"] < 0.5 else 1)
PY

for bad in seed:15.4,-1.5 seed:15.4,-1.5,16,2 seed:a,b,c seed:1500,0,0; do
  "$DYNSUB" segment "$templates/ch2.nii.gz" --init "$bad" --no-figures --out "$work/bad_seed" >"$work/bad.log" 2>&1
  check "--init $bad: a clear error, no output" bash -c "test $? -ne 0 && grep -q 'seed' '$work/bad.log' && test ! -e '$work/bad_seed'"
done

echo "$failures failure(s)"
test "$failures" -eq 0
