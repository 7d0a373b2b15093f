#!/usr/bin/env bash
# dynsub-bids, the BIDS App, on the cohort of make_cohort.py (sub-01: the
# caudate and putamen from landmarks and the thalamus from a seed, in one
# job; sub-02: a moved copy; sub-03 ses-2: the 0.5 mm MRI), with its
# outputs in derivatives/dynsub as most users keep them:
#  - `participant --participant-label 01` segments sub-01 only and writes no
#    group table; sub-02 and sub-03 then run at once, in two processes on one
#    output folder, spelt the BIDS Apps way (--participant_label, sub- prefix,
#    --session_label);
#  - `group` writes the table and the QC page of the three jobs, starting no
#    segmentation; a rerun of a participant does nothing;
#  - the derivatives keep the naming rules (check_derivatives.py), and the
#    official BIDS validator (npm bids-validator 1.x) finds no error in the
#    dataset with its derivatives in place, while it does find the outputs
#    misplaced at the dataset's top level (so the check can fail);
#  - `group` again, with options that would segment anew and an image
#    touched, still segments nothing; a labelmap of a subject the dataset
#    no longer has is warned of;
#  - mistakes are refused with a message and nothing written: a label that
#    selects nothing, the group level before any participant, a missing
#    dataset, a malformed dataset_description.json, an unknown level, the
#    dataset as its own output through a link, an output folder in the
#    dataset outside derivatives/, a work directory with a space, a
#    structure seeded twice;
#  - a seeds table with a byte order mark is read, and a T1w without
#    landmarks or a seed is warned of once, when its participant is chosen.
# Needs DYNSUB_BIDS, DATA, WORKFLOWS, BIDS_VALIDATOR; snakemake, nibabel.
set -u
source "$DATA/../Applications/dynsub/test/Checks.sh"
require_colin27
here=$(dirname "${BASH_SOURCE[0]}")
python=/usr/bin/python3
if [ ! -x "$BIDS_VALIDATOR" ]; then
  echo "FAILED: $BIDS_VALIDATOR is missing (./run test installs npm's bids-validator into build/test-npm)"
  exit 1
fi
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cd "$work"
bids="$work/bids"
out="$bids/derivatives/dynsub"
"$python" "$here/make_cohort.py" "$templates" "$DATA" "$bids"

"$DYNSUB_BIDS" "$bids" "$out" participant --participant-label 01 --cores 2 >"$work/p1.log" 2>&1
check "participant 01: exit 0" test $? -eq 0 || tail -30 "$work/p1.log"
check "participant 01: its one job's labelmap" \
  test "$(find "$out/sub-01/anat" -name '*_dseg.nii.gz' | wc -l)" -eq 1
check "participant 01: no other subject" test ! -e "$out/sub-02" -a ! -e "$out/sub-03"
check "participant 01: no group table" test ! -e "$out/segmentations.tsv"
check "participant 01: dataset_description.json and .bidsignore" \
  test -s "$out/dataset_description.json" -a -s "$out/.bidsignore"

# Two participant runs at once on one output folder, as a cluster's array
# job would start them.
"$DYNSUB_BIDS" "$bids" "$out" participant --participant_label sub-02 --cores 1 >"$work/p2.log" 2>&1 &
second=$!
"$DYNSUB_BIDS" "$bids" "$out" participant --participant_label 03 --session_label 2 --cores 1 >"$work/p3.log" 2>&1
third=$?
wait $second
check "participants 02 and 03 at once: both exit 0" test $? -eq 0 -a $third -eq 0 ||
  tail -30 "$work/p2.log" "$work/p3.log"

"$DYNSUB_BIDS" "$bids" "$out" group >"$work/group.log" 2>&1
check "group: exit 0" test $? -eq 0 || tail -30 "$work/group.log"
check "group: no segmentation run" test "$(grep -c '^rule segment:' "$work/group.log")" -eq 0
check "group: table and QC page" test -s "$out/segmentations.tsv" -a -s "$out/report.html"
check "group: the six structures, all ok" "$python" - "$out/segmentations.tsv" <<'PY'
import csv, sys
rows = list(csv.DictReader(open(sys.argv[1]), delimiter="\t"))
assert [(r["participant_id"], r["session_id"], r["structure"], r["status"]) for r in rows] == [
    ("sub-01", "n/a", "caudateL", "ok"), ("sub-01", "n/a", "putamenL", "ok"), ("sub-01", "n/a", "thalamusL", "ok"),
    ("sub-02", "n/a", "caudateL", "ok"), ("sub-02", "n/a", "putamenL", "ok"), ("sub-03", "ses-2", "caudateL", "ok")], rows
assert float(rows[0]["dice"]) >= 0.84, rows[0]  # the workflow test's bar on the demo's caudate (0.853)
PY
check "derivatives: BIDS names, sidecars, grids" "$python" "$here/check_derivatives.py" "$bids" "$out" 3

touch "$work/marker"
"$DYNSUB_BIDS" "$bids" "$out" participant --participant-label 01 --cores 2 >"$work/rerun.log" 2>&1
check "rerun of participant 01: exit 0, nothing to be done" grep -q "Nothing to be done" "$work/rerun.log"
check "rerun of participant 01: no file rewritten" \
  test -z "$(find "$out" -newer "$work/marker" -type f -not -path '*/work/*')"
# The group level summarizes what is there, whatever options it is given
# and whatever changed since: options that would make a participant run
# segment again, and an image touched.
touch "$bids/sub-02/anat/sub-02_T1w.nii.gz"
"$DYNSUB_BIDS" "$bids" "$out" group --segment-args "--max-level 0" >"$work/group2.log" 2>&1
check "group with other options, an image touched: exit 0" test $? -eq 0 || tail -30 "$work/group2.log"
check "group with other options, an image touched: no segmentation run" \
  test "$(grep -c 'rule segment' "$work/group2.log")" -eq 0
check "group with other options, an image touched: no labelmap rewritten" \
  test -z "$(find "$out" -newer "$work/marker" -name '*_dseg.nii.gz')"

# The official validator, on the raw dataset with the derivatives in place.
validate() {  # validate DIR: prints the validator's errors and warnings by code; exit 1 on an error
  "$BIDS_VALIDATOR" --json "$1" 2>/dev/null | "$python" -c '
import json, sys
result = json.load(sys.stdin)
errors, warnings = result["issues"]["errors"], result["issues"]["warnings"]
print("subjects:", result["summary"]["subjects"], "errors:", [e["key"] for e in errors],
      "warnings:", [w["key"] for w in warnings])
sys.exit(1 if errors or result["summary"]["subjects"] != ["01", "02", "03"] else 0)'
}
check "bids-validator: no error with the outputs in derivatives/dynsub" validate "$bids"
cp -r "$bids" "$work/misplaced" && cp -r "$out"/. "$work/misplaced/"
invalid() { ! validate "$1"; }
check "bids-validator: the same outputs at the dataset's top level are errors" invalid "$work/misplaced"

# A labelmap of a subject the dataset no longer has is named at the group
# level, and left out of the table.
mkdir -p "$out/sub-07/anat"
cp "$out/sub-02/anat/sub-02_space-orig_dseg.nii.gz" "$out/sub-07/anat/sub-07_space-orig_dseg.nii.gz"
"$DYNSUB_BIDS" "$bids" "$out" group >"$work/group3.log" 2>&1
check "group with an earlier run's labelmap: exit 0" test $? -eq 0 || tail -30 "$work/group3.log"
check "group with an earlier run's labelmap: warned of by name" \
  grep -q "warning: $out/sub-07/anat/sub-07_space-orig_dseg.nii.gz: left by an earlier run" "$work/group3.log"
check "group with an earlier run's labelmap: only that one" test "$(grep -c 'left by an earlier run' "$work/group3.log")" -eq 1
check "group with an earlier run's labelmap: not in the table" test -z "$(grep sub-07 "$out/segmentations.tsv")"
rm -r "$out/sub-07"

"$DYNSUB_BIDS" "$bids" "$work/fresh" participant --participant-label 09 >"$work/bad.log" 2>&1
check "an unknown participant: exit 1" test $? -eq 1
check "an unknown participant: named" grep -q "sub-09: no T1w image with landmarks or a seed" "$work/bad.log"
check "an unknown participant: nothing written" test ! -e "$work/fresh"
"$DYNSUB_BIDS" "$bids" "$work/fresh" group >"$work/bad.log" 2>&1
check "group before participant: exit 1, says so" grep -q "run the participant level first" "$work/bad.log"
check "group before participant: nothing written" test ! -e "$work/fresh"
"$DYNSUB_BIDS" "$work/nowhere" "$work/fresh" participant >"$work/bad.log" 2>&1
check "a missing dataset: exit 2, named" test $? -eq 2 -a -n "$(grep "nowhere: no such BIDS directory" "$work/bad.log")"
mkdir "$work/broken"
printf '{"Name": "cohort", "BIDSVersion": "1.9.0",' >"$work/broken/dataset_description.json"
"$DYNSUB_BIDS" "$work/broken" "$work/fresh" participant >"$work/bad.log" 2>&1
check "a truncated dataset_description.json: exit 2, named" \
  test $? -eq 2 -a -n "$(grep "broken/dataset_description.json: not readable as JSON" "$work/bad.log")"
printf '{"Name": "cohort"}' >"$work/broken/dataset_description.json"
"$DYNSUB_BIDS" "$work/broken" "$work/fresh" participant >"$work/bad.log" 2>&1
check "a dataset_description.json without BIDSVersion: exit 2, named" \
  test $? -eq 2 -a -n "$(grep "dataset_description.json: no BIDSVersion" "$work/bad.log")"
printf '{"Name": "cohort", "BIDSVersion": 1.9}' >"$work/broken/dataset_description.json"
"$DYNSUB_BIDS" "$work/broken" "$work/fresh" participant >"$work/bad.log" 2>&1
check "a dataset_description.json with a number for BIDSVersion: exit 2, named" \
  test $? -eq 2 -a -n "$(grep "dataset_description.json: BIDSVersion is 1.9, not text" "$work/bad.log")"
printf '["cohort"]' >"$work/broken/dataset_description.json"
"$DYNSUB_BIDS" "$work/broken" "$work/fresh" participant >"$work/bad.log" 2>&1
check "a dataset_description.json that is a list: exit 2, named" \
  test $? -eq 2 -a -n "$(grep "dataset_description.json: not a JSON object" "$work/bad.log")"
check "a malformed dataset_description.json: nothing written" test ! -e "$work/fresh"
"$DYNSUB_BIDS" "$bids" "$work/fresh" subject >"$work/bad.log" 2>&1
check "an unknown level: exit 2" test $? -eq 2
"$DYNSUB_BIDS" "$bids" "$work/fresh" participant --profile "$work" >"$work/bad.log" 2>&1
check "a folder that is not a profile: exit 2, named" test $? -eq 2 -a -n "$(grep "not a Snakemake profile" "$work/bad.log")"
"$DYNSUB_BIDS" "$bids" "$work/fresh" participant --participant-label 0_1 >"$work/bad.log" 2>&1
check "a malformed label: exit 2" test $? -eq 2
ln -s "$bids" "$work/link"
cp "$bids/dataset_description.json" "$work/description"
"$DYNSUB_BIDS" "$work/link" "$bids" participant >"$work/bad.log" 2>&1
check "the dataset as its own output through a link: exit 2" \
  test $? -eq 2 -a -n "$(grep "must not be the BIDS dataset itself" "$work/bad.log")"
check "the dataset as its own output through a link: its description kept" \
  cmp -s "$bids/dataset_description.json" "$work/description"
"$DYNSUB_BIDS" "$bids" "$bids/dynsub" participant >"$work/bad.log" 2>&1
check "an output folder in the dataset outside derivatives/: exit 2, the fix named" \
  test $? -eq 2 -a -n "$(grep "not in its derivatives folder.*use $bids/derivatives/dynsub" "$work/bad.log")"
check "an output folder in the dataset outside derivatives/: nothing written" test ! -e "$bids/dynsub"
"$DYNSUB_BIDS" "$bids" "$work/with space" participant >"$work/bad.log" 2>&1
check "a work directory with a space: exit 2, named" \
  test $? -eq 2 -a -n "$(grep "path has a space" "$work/bad.log")"
cp "$bids/derivatives/seeds.tsv" "$work/seeds.tsv"
tail -n 1 "$work/seeds.tsv" | awk -F'\t' -v OFS='\t' '{ $NF = $NF + 1; print }' >>"$work/seeds.tsv"
"$DYNSUB_BIDS" "$bids" "$work/fresh" participant --seeds "$work/seeds.tsv" >"$work/bad.log" 2>&1
check "a structure seeded twice: exit 1, named" \
  test $? -eq 1 -a -n "$(grep "seeds.tsv:[0-9]*: a second seed for sub-01 thalamusL" "$work/bad.log")"
check "a structure seeded twice: nothing written" test ! -e "$work/fresh"
# Excel's "CSV UTF-8" starts the seeds table with a byte order mark.
printf '\xef\xbb\xbf' | cat - "$bids/derivatives/seeds.tsv" >"$work/bom.tsv"
"$DYNSUB_BIDS" "$bids" "$work/fresh" participant --seeds "$work/bom.tsv" --dry-run >"$work/bom.log" 2>&1
check "a seeds table with a byte order mark: read" test $? -eq 0 || tail -5 "$work/bom.log"
# A T1w with neither landmarks nor a seed is named once, when its
# participant is chosen.
cp -r "$bids" "$work/extra"
mkdir -p "$work/extra/sub-05/anat"
cp "$bids/sub-02/anat/sub-02_T1w.nii.gz" "$work/extra/sub-05/anat/sub-05_T1w.nii.gz"
"$DYNSUB_BIDS" "$work/extra" "$work/fresh" participant --dry-run >"$work/extra.log" 2>&1
check "a T1w without landmarks: warned of once" \
  test "$(grep -c "sub-05_T1w.nii.gz: not segmented: no landmarks" "$work/extra.log")" -eq 1
"$DYNSUB_BIDS" "$work/extra" "$work/fresh" participant --participant-label 01 --dry-run >"$work/extra.log" 2>&1
check "a T1w without landmarks, its participant not chosen: not warned of" \
  test "$(grep -c "sub-05_T1w.nii.gz: not segmented" "$work/extra.log")" -eq 0

echo "$failures failure(s)"
exit $((failures > 0))
