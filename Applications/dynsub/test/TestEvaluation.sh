#!/usr/bin/env bash
# dynsub evaluate on the reduced plan (Data/Evaluation/ci_plan.json: 7
# structures of the test split x 3 protocols x 1 seed on Colin27 at 1 mm),
# and its refusals of bad plans.
#
# What is asserted: every run completes and is scored; a run that collapses
# (less than a fifth of the reference's volume) was warned of by segment or
# by the seed's growth, without the reference; and each protocol's mean Dice
# stays at or above what this code measures today, as a guard against
# regressions (0.769 for six slices, 0.763 for three and 0.41 from one seed
# click; the floors leave 0.06-0.08: the runs are deterministic, so the
# margin only absorbs another compiler's rounding). These are NOT the targets of the
# evaluation's issue (mean Dice >= 0.85 from <= 40 points on <= 6 slices,
# >= 0.75-0.80 from one click): those are not met yet, see
# Documentation/Segmentation.md.
# Needs DYNSUB (the executable) and DATA.
set -u
source "$(dirname "${BASH_SOURCE[0]}")/Checks.sh"
require_colin27
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

# The directory holds an earlier evaluation's plot of another split and a
# file of the user's.
mkdir "$work/eval"
echo '<svg/>' >"$work/eval/dice_tuning.svg"
echo mine >"$work/eval/notes.txt"
"$DYNSUB" evaluate "$DATA/Evaluation/ci_plan.json" --out "$work/eval" --jobs 2 >"$work/eval.log" 2>&1
check "evaluate succeeds" test $? -eq 0
cat "$work/eval.log"
for f in runs.csv summary.csv summary.json dice_test.svg; do
  check "evaluate writes $f" test -s "$work/eval/$f"
done
check "evaluate removes an earlier plot of a split it did not run, and keeps the user's file" \
  test ! -e "$work/eval/dice_tuning.svg" -a -e "$work/eval/notes.txt"
check "21 runs, all scored, every collapse warned of, Dice floors hold" python3 - "$work/eval/runs.csv" <<'PY'
import csv, sys
rows = list(csv.DictReader(open(sys.argv[1])))
ok = len(rows) == 21
for r in rows:
    if r["error"]:
        print("run failed:", r); ok = False
    if r["collapsed"] == "1" and "collapse" not in r["warnings"]:
        print("a collapse was not warned of:", r); ok = False
    if r["protocol"] != "seed" and int(r["landmarks"]) != {"six_slices": 36, "sparse": 15}[r["protocol"]]:
        print("wrong number of clicks:", r); ok = False
    if not (0 <= float(r["surface_on_edges"]) <= 1):
        print("surface_on_edges out of range:", r); ok = False
    if r["protocol"] != "seed" and not (0 < float(r["dice"]) <= 1):
        print("Dice out of range:", r); ok = False
    # One click alone is flagged; clicks on slices outline a volume to compare with.
    if (r["protocol"] == "seed") != ("one_click" in r["trust_flags"].split()):
        print("one_click flag wrong:", r); ok = False
    if r["protocol"] != "seed" and not float(r["trust_volume_ratio"]) > 0:
        print("no volume ratio for clicks on slices:", r); ok = False
    # Every run starts from a model with a volume, whatever started it.
    if not float(r["trust_initial_volume_ratio"]) > 0:
        print("no ratio to the initial model's volume:", r); ok = False
    # A measure not taken (the atlas's: this plan has none) is empty, as the README says.
    if any(v.strip().lower().lstrip("-") in ("nan", "inf") for v in r.values()):
        print("a field reads nan or inf:", r); ok = False
    if r["trust_atlas_outline_distance_mm"] != "":
        print("an atlas measure without an atlas:", r); ok = False
for protocol, floor in (("six_slices", 0.70), ("sparse", 0.68), ("seed", 0.35)):
    dice = [float(r["dice"]) for r in rows if r["protocol"] == protocol]
    mean = sum(dice) / len(dice)
    print(f"{protocol}: mean Dice {mean:.3f} over {len(dice)} runs (floor {floor})")
    ok = ok and mean >= floor
formats = {r["format"] for r in rows if r["protocol"] != "seed"}
ok = ok and formats <= {"mrk.json", "fcsv", "csv"} and len(formats) >= 1
sys.exit(0 if ok else 1)
PY
check "the SVG plot is well-formed XML" python3 -c "import sys, xml.dom.minidom; xml.dom.minidom.parse(sys.argv[1])" \
  "$work/eval/dice_test.svg"

# Cohorts of generated subjects (SubjectGenerator.h): one single-scan test
# subject (SNR 20-30) made from Colin27 and AAL, and one synthesized from
# their labels with a T2-like contrast; two structures, six slices of
# clicks. Each run is scored against the subject's own moved labels.
cat >"$work/cohort.json" <<'JSON'
{"cohorts": [{"name": "single_scan", "image": "/usr/share/mricron/templates/ch2.nii.gz",
  "labels": "/usr/share/mricron/templates/aal.nii.gz", "settings": {"snr": [20, 30]},
  "subjects": {"tuning": [1], "test": [101]}},
 {"name": "synthesized", "image": "/usr/share/mricron/templates/ch2.nii.gz",
  "labels": "/usr/share/mricron/templates/aal.nii.gz",
  "settings": {"mode": "synthesized", "t2_fraction": 1, "snr": [20, 30], "structure_labels": [74, 77]},
  "subjects": {"test": [501]}}],
 "structures": [{"name": "putamen_right", "labels": [74], "orientation": "coronal"},
                {"name": "thalamus_left", "labels": [77], "orientation": "coronal"}],
 "protocols": [{"name": "six_slices", "slices": 6, "points_per_slice": 6, "coverage": [0.6, 0.8],
                "scatter_mm": 0.4, "format": "rotate"}],
 "splits": [{"name": "tuning", "seeds": [1]}, {"name": "test", "seeds": [101]}]}
JSON
"$DYNSUB" evaluate "$work/cohort.json" --split test --out "$work/cohort" >"$work/cohort.log" 2>&1
check "evaluate runs a cohort" test $? -eq 0
# Only the test subjects run in the test split; floors as above (the
# measured Dice less 0.05-0.06: 0.832 and 0.864 on the single scan, 0.867 and
# 0.921 on the synthesized one).
check "a cohort's test subject, scored against its own labels" python3 - "$work/cohort/runs.csv" <<'PY'
import csv, sys
runs = list(csv.DictReader(open(sys.argv[1])))
assert len(runs) == 4, len(runs)
assert not any(r["error"] for r in runs), runs
cohorts = {("single_scan", "s101", "source"), ("synthesized", "s501", "t2")}
assert {(r["image"], r["subject"], r["contrast"]) for r in runs} == cohorts, runs
assert all(20 <= float(r["subject_snr"]) <= 30 for r in runs), runs
floors = {("single_scan", "putamen_right"): 0.77, ("single_scan", "thalamus_left"): 0.80,
          ("synthesized", "putamen_right"): 0.82, ("synthesized", "thalamus_left"): 0.86}
for r in runs:
    assert float(r["dice"]) >= floors[(r["image"], r["structure"])], (r["image"], r["structure"], r["dice"])
PY

# Bad plans: a clear error naming the file, a non-zero exit, no output.
bad() {  # bad NAME PLAN-TEXT EXPECTED-MESSAGE
  local name=$1 text=$2 expected=$3
  printf '%s' "$text" >"$work/$name.json"
  "$DYNSUB" evaluate "$work/$name.json" --out "$work/out_$name" >"$work/$name.log" 2>&1
  local status=$?
  check "$name: non-zero exit" test $status -ne 0
  check "$name: the error names the plan and the problem" grep -q "$name.json.*$expected" "$work/$name.log"
  check "$name: no output" test ! -e "$work/out_$name/runs.csv"
}
# edited 'STATEMENT': the CI plan with the Python statement applied to it (as p).
edited() {
  python3 -c "import json, sys; p = json.load(open(sys.argv[1])); $1; print(json.dumps(p))" \
    "$DATA/Evaluation/ci_plan.json"
}
bad not_json '{"reference": ' "not valid JSON"
bad no_splits '{"reference": "x.nii.gz", "images": [], "structures": [], "protocols": [], "splits": []}' \
  "needs images or cohorts, structures, protocols and splits"
bad unknown_structure "$(edited "p['splits'][0]['structures'] = ['nucleus_x']")" "unknown structure 'nucleus_x'"
bad bad_protocol "$(edited "p['protocols'][0]['coverage'] = [0.9, 0.2]")" "coverage"
# Whole numbers are whole: 1.5 slices or a seed of -1 is refused, not read as 1 or 4294967295.
bad fractional_slices "$(edited "p['protocols'][0]['slices'] = 1.5")" "slices must be a whole number, got 1.5"
bad negative_seed "$(edited "p['splits'][0]['seeds'] = [-1]")" "a seed must be in 0..4294967295, got -1"
bad fractional_level "$(edited "p['segment'] = {'max_level': 1.5}")" "segment setting max_level (--max-level) must be a whole number"
bad unknown_setting "$(edited "p['segment'] = {'sigma': 1}")" "unknown segment setting 'sigma'"
bad duplicate_structure "$(edited "p['structures'].append(p['structures'][0])")" "two structures are named 'caudate_left'"
bad escaping_name "$(edited "p['splits'][0]['name'] = '../../escaped'")" \
  "'../../escaped' is not a usable name for one of the splits"
bad misspelt_key "$(edited "p['protocols'][0]['slice'] = 6")" "a protocol: unknown key 'slice'"
bad repeated_seed "$(edited "p['splits'][0]['seeds'] = [101, 101]")" "split 'test' lists seed 101 twice"
bad no_seeds "$(edited "p['splits'][0]['seeds'] = []")" "split 'test' has no seeds"
# A split that would run nothing: an atlas start is not measured on the
# atlas's own template, which is the plan's one image.
bad atlas_on_its_template "$(edited "p['protocols'] = [{'name': 'atlas', 'atlas': True, 'clicks': False}]")" \
  "split 'test' has no run: its protocols all start from the atlas, and its images are the atlas's template"
# A reference placed 500 mm off the image (its header's qoffset_x and
# srow_x[3] moved) is refused, naming the reference, before any run.
python3 -c "
import gzip, struct, sys
header = bytearray(gzip.open(sys.argv[1]).read())
for offset in (268, 292):  # qoffset_x, srow_x[3]
    struct.pack_into('<f', header, offset, struct.unpack_from('<f', header, offset)[0] + 500)
open(sys.argv[2], 'wb').write(header)" /usr/share/mricron/templates/aal.nii.gz "$work/aal_far.nii"
edited "p['reference'] = '$work/aal_far.nii'" >"$work/reference_far.json"
expect_error "a reference off the image" 1 "aal_far.nii: structure '[a-z_]*' lies wholly outside image 'colin27_1mm'" \
  "$work/out_far/runs.csv" "$DYNSUB" evaluate "$work/reference_far.json" --out "$work/out_far"
expect_error "an unknown --split" 2 "--split nope: the plan has no such split (its splits: test)" \
  "$work/out_nope/runs.csv" "$DYNSUB" evaluate "$DATA/Evaluation/ci_plan.json" --split nope --out "$work/out_nope"
# A plan whose every run fails (3 clicks on one slice make no surface) is
# not a result: the runs are written, with their errors, and the exit is 1.
edited "p['protocols'] = [dict(p['protocols'][0], slices=1, points_per_slice=3)]; \
p['splits'][0]['structures'] = ['caudate_left', 'putamen_left']" >"$work/all_fail.json"
"$DYNSUB" evaluate "$work/all_fail.json" --out "$work/out_all_fail" >"$work/all_fail.log" 2>&1
check "a plan whose every run fails: exit 1" test $? -eq 1
check "a plan whose every run fails: the message" grep -q "all_fail.json: every one of its 2 runs failed" \
  "$work/all_fail.log"
check "a plan whose every run fails: runs.csv gives the errors" test -s "$work/out_all_fail/runs.csv"
"$DYNSUB" evaluate "$work/missing.json" --out "$work/out_missing" >"$work/missing.log" 2>&1
check "missing plan: non-zero exit and the file named" grep -q "missing.json" "$work/missing.log"
"$DYNSUB" evaluate "$DATA/Evaluation/ci_plan.json" --out "$work/out_keep" --keep-landmarks "$work/no/clicks" \
  >"$work/keep.log" 2>&1
check "--keep-landmarks under a missing folder: non-zero exit, the folder named, nothing made" \
  test $? -ne 0 -a ! -e "$work/no" -a ! -e "$work/out_keep/runs.csv"
check "--keep-landmarks under a missing folder: the message" grep -q "no/clicks: cannot be created" "$work/keep.log"

echo "$failures failure(s)"
test "$failures" -eq 0
