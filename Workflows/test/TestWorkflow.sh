#!/usr/bin/env bash
# The Snakemake cohort workflow (Workflows/Snakefile) on a small BIDS cohort
# made from Colin27 (make_cohort.py): the 1 mm MRI with two structures'
# landmarks and a seed click from a seeds table (one job: the three
# segmented together), a rigidly moved copy with its two
# structures' landmarks (.fcsv, RAS) and reference moved along, the 0.5 mm
# MRI in a session (.csv landmarks).
#  - `snakemake --cores 2` writes derivatives that keep the BIDS naming rules
#    (check_derivatives.py), the group table and the QC page; the moved copy
#    scores what the original does (Dice within 0.01);
#  - a second run does nothing;
#  - a broken subject (a truncated T1w) fails alone under --keep-going: no
#    output of its own, the others untouched, the table and the page list it;
#  - the Slurm profile's dry run passes (TestSlurm.sh runs it on a real
#    one-node cluster);
#  - the QC page renders in headless Chromium without console messages, and
#    driven by Playwright (check_qc_page.js) it sorts, keeps and exports
#    ratings, and its interactive NiiVue view draws;
#  - bad configurations fail with a clear message; a T1w name the workflow
#    does not handle is skipped with a warning.
# Needs DYNSUB, DATA, WORKFLOWS, NIIVUE (niivue.umd.js) and NODE_PATH (with
# playwright-core); snakemake, python3-nibabel, python3-bids-validator,
# chromium and node.
set -u
source "$DATA/../Applications/dynsub/test/Checks.sh"
require_colin27
here=$(dirname "${BASH_SOURCE[0]}")
python=/usr/bin/python3
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cd "$work"
snake() { snakemake -s "$WORKFLOWS/Snakefile" --config bids="$work/bids" dynsub="$DYNSUB" niivue="$NIIVUE" "$@"; }

"$python" "$here/make_cohort.py" "$templates" "$DATA" "$work/bids"
check "cohort made" test -s "$work/bids/sub-02/anat/sub-02_T1w.nii.gz"

snake out="$work/out" --cores 2 >"$work/run1.log" 2>&1
check "first run: exit 0" test $? -eq 0 || tail -40 "$work/run1.log"
check "first run: BIDS derivative names, sidecars, grids (and the raw cohort valid BIDS)" \
  "$python" "$here/check_derivatives.py" "$work/bids" "$work/out" 3
cat "$work/out/segmentations.tsv"
check "group table: 6 structures in 3 jobs, the moved copy as good as the original" "$python" - "$work/out" <<'PY'
import csv, json, os, sys
rows = {(r["participant_id"], r["session_id"], r["structure"]): r
        for r in csv.DictReader(open(sys.argv[1] + "/segmentations.tsv"), delimiter="\t")}
original, moved = rows[("sub-01", "n/a", "caudateL")], rows[("sub-02", "n/a", "caudateL")]
putamen, moved_putamen = rows[("sub-01", "n/a", "putamenL")], rows[("sub-02", "n/a", "putamenL")]
fine = rows[("sub-03", "ses-2", "caudateL")]
seed = rows[("sub-01", "n/a", "thalamusL")]
assert len(rows) == 6 and all(r["status"] == "ok" for r in rows.values()), rows
# The caudate, the putamen and the thalamus from its seed share one labelmap
# (values 1-3, the structures with landmarks first; check_derivatives checks
# that it holds them all).
assert original["dseg"] == putamen["dseg"] == seed["dseg"] == "sub-01/anat/sub-01_space-orig_dseg.nii.gz", \
    (original, putamen, seed)
assert (original["index"], putamen["index"], seed["index"]) == ("1", "2", "3"), (original, putamen, seed)
# The sidecar keeps the seeded structure's click, as the seeds table gives it.
sidecar = json.load(open(sys.argv[1] + "/sub-01/anat/sub-01_space-orig_dseg.json"))
entries = {e["Name"]: e for e in sidecar["Structures"]}
click = next(csv.DictReader(open(os.path.dirname(sys.argv[1]) + "/bids/derivatives/seeds.tsv"), delimiter="\t"))
assert entries["thalamusL"]["SeedLPS"] == [float(click[c]) for c in "xyz"] and "SeedLPS" not in entries["caudateL"], \
    entries
assert float(original["dice"]) >= 0.84, original          # the demo's 0.850 alone, 0.853 with the putamen
assert float(putamen["dice"]) >= 0.88, putamen          # measured 0.890 with the caudate
assert abs(float(moved["dice"]) - float(original["dice"])) <= 0.01, (moved, original)  # rigid motion changes nothing
assert abs(float(moved_putamen["dice"]) - float(putamen["dice"])) <= 0.01, (moved_putamen, putamen)
assert fine["dice"] == "n/a" and abs(float(fine["volume_mm3"]) / float(original["volume_mm3"]) - 1) < 0.15, fine
# The T1w's entities are carried into its outputs' names.
assert fine["dseg"] == "sub-03/ses-2/anat/sub-03_ses-2_acq-hires_run-1_space-orig_desc-caudateL_dseg.nii.gz", fine
assert float(seed["dice"]) >= 0.4, seed                   # one click: measured 0.517
PY
check "QC page written" test -s "$work/out/report.html"
check ".bidsignore names the workflow's own files" grep -q "^logs/$" "$work/out/.bidsignore"

# T1w names with entities (acq-, run-, ...) are jobs of their own; others
# are skipped with a warning, never fatal; a reference found but not used is
# warned of.
check "entities carried through, unknown ones skipped, unused references warned of" \
  "$python" - "$WORKFLOWS" "$work/entities" <<'PY'
import os, sys
sys.path.insert(0, sys.argv[1])
import dynsub_bids as bids
root = sys.argv[2]
def touch(path, text=""):
    os.makedirs(os.path.dirname(path), exist_ok=True)
    open(path, "w").write(text)
for name in ("sub-04/anat/sub-04_run-1", "sub-05/anat/sub-05_acq-mprage_run-1", "sub-05/anat/sub-05_acq-mprage_run-2",
             "sub-06/anat/sub-06_foo-1", "sub-06/anat/sub-06_run-1_chunk-1"):
    touch(f"{root}/{name}_T1w.nii.gz")
landmarks, reference = f"{root}/derivatives/landmarks", f"{root}/derivatives/reference"
touch(f"{landmarks}/sub-04/anat/sub-04_desc-caudateL_landmarks.csv")  # no entities: the session's one T1w
touch(f"{landmarks}/sub-05/anat/sub-05_acq-mprage_run-2_desc-caudateL_landmarks.csv")
touch(f"{reference}/sub-04/anat/sub-04_dseg.nii.gz")
touch(f"{reference}/sub-04/anat/sub-04_dseg.tsv", "index\tname\n3\tcaudateL\n")  # its own table
touch(f"{reference}/sub-05/anat/sub-05_acq-mprage_run-2_dseg.nii.gz")  # no table names its labels
warnings = []
structures = bids.find_structures(root, landmarks, None, reference, warn=warnings.append)
assert sorted(structures) == [("sub-04_run-1", "caudateL"), ("sub-05_acq-mprage_run-2", "caudateL")], sorted(structures)
# The folders given with a trailing slash find the same.
again = bids.find_structures(root + "/", landmarks + "/", None, reference + "/", warn=lambda message: None)
assert sorted(again) == sorted(structures), sorted(again)
structure = structures[("sub-04_run-1", "caudateL")]
assert structure.t1w.endswith("sub-04_run-1_T1w.nii.gz") and structure.reference_labels == [3], vars(structure)
jobs = bids.group_jobs(structures)
assert bids.job_paths("/o", jobs[("sub-04_run-1", "_desc-caudateL")])["dseg"] == \
    "/o/sub-04/anat/sub-04_run-1_space-orig_desc-caudateL_dseg.nii.gz"
assert any("sub-06_foo-1_T1w.nii.gz: skipped" in w for w in warnings), warnings
assert any("sub-06_run-1_chunk-1_T1w.nii.gz: skipped" in w for w in warnings), warnings  # chunk- follows space-
assert any("not used for caudateL" in w for w in warnings), warnings
# Two structures' landmarks and a third's seed for one image are one job,
# named by no structure, the structures with landmarks first; a reference
# that names only one of them scores none, with a warning.
touch(f"{landmarks}/sub-04/anat/sub-04_desc-putamenL_landmarks.csv")
seeds = f"{root}/seeds.tsv"
touch(seeds, "participant_id\tstructure\tx\ty\tz\nsub-04\tthalamusL\t1\t2\t3\n")
warnings = []
jobs = bids.group_jobs(bids.find_structures(root, landmarks, seeds, reference, warn=warnings.append),
                       warn=warnings.append)
assert sorted(jobs) == [("sub-04_run-1", ""), ("sub-05_acq-mprage_run-2", "_desc-caudateL")], sorted(jobs)
together = jobs[("sub-04_run-1", "")]
assert [s.name for s in together.structures] == ["caudateL", "putamenL", "thalamusL"], vars(together)
assert together.reference is None and together.seeds == [None, None, (1.0, 2.0, 3.0)], vars(together)
assert bids.job_paths("/o", together)["dseg"] == "/o/sub-04/anat/sub-04_run-1_space-orig_dseg.nii.gz"
assert any("not used for caudateL either" in w for w in warnings), warnings
touch(f"{landmarks}/sub-05/anat/sub-05_desc-putamenL_landmarks.csv")  # which of two runs?
try:
    bids.find_structures(root, landmarks, None, reference, warn=warnings.append)
    sys.exit("a landmark file that fits two T1w images was taken")
except bids.CohortError as error:
    assert "has 2 T1w images" in str(error), error
os.remove(f"{landmarks}/sub-05/anat/sub-05_desc-putamenL_landmarks.csv")
touch(f"{landmarks}/sub-05/anat/sub-04_run-1_desc-pallidumL_landmarks.csv")  # copied, not renamed
try:
    bids.find_structures(root, landmarks, None, reference, warn=warnings.append)
    sys.exit("a landmark file in another subject's folder was taken")
except bids.CohortError as error:
    assert "sub-04_run-1_desc-pallidumL_landmarks.csv: its name is for sub-04/anat, not the folder" in str(error), error
# The derivatives' link to the raw dataset is a URI, whatever its path holds.
import json
bids.write_dataset_description(f"{root}/description.json", "1.0", "/data/my study#2")
assert json.load(open(f"{root}/description.json"))["DatasetLinks"]["raw"] == "file:///data/my%20study%232"
PY

touch "$work/marker"
snake out="$work/out" --cores 2 >"$work/run2.log" 2>&1
check "second run: exit 0" test $? -eq 0
check "second run: nothing to be done" grep -q "Nothing to be done" "$work/run2.log"
check "second run: no file rewritten" test -z "$(find "$work/out" -newer "$work/marker" -type f)"

"$python" "$here/make_cohort.py" "$templates" "$DATA" "$work/bids" --broken
touch "$work/marker"
snake out="$work/out" --cores 2 --keep-going >"$work/run3.log" 2>&1
check "broken subject: the run exits non-zero" test $? -ne 0
check "broken subject: only its job ran" test "$(grep -c '^rule segment:' "$work/run3.log")" -eq 1
check "broken subject: its failure names its T1w" grep -q "sub-04_T1w.nii.gz" "$work/run3.log"
check "broken subject: no output of its own" test -z "$(find "$work/out/sub-04" -type f 2>/dev/null)"
check "broken subject: no work directory left" test -z "$(find "$work/out" -name '.work-*')"
check "broken subject: the others untouched" \
  test -z "$(find "$work/out/sub-0"[123] -newer "$work/marker" -type f)"
check "broken subject: listed as failed in the group table" \
  grep -q -P "^sub-04\tn/a\tcaudateL\tfailed\t.*sub-04_T1w" "$work/out/segmentations.tsv"
check "broken subject: flagged on the QC page" grep -q '<span class="flag">failed</span>' "$work/out/report.html"

snake out="$work/cluster" --profile "$WORKFLOWS/profiles/slurm" -n >"$work/dry.log" 2>&1
check "Slurm profile: dry run exits 0" test $? -eq 0
check "Slurm profile: dry run plans 4 segmentations" grep -q -P "^segment\s+4\s" "$work/dry.log"
check "Slurm profile: dry run writes nothing" test ! -e "$work/cluster/segmentations.tsv"
rm "$work/bids/sub-04" "$work/bids/derivatives/landmarks/sub-04" -r  # the broken subject, done with

chromium --headless=new --no-sandbox --disable-gpu --hide-scrollbars --window-size=1400,2200 --enable-logging=stderr \
  --v=0 --screenshot="$work/report.png" "file://$work/out/report.html" >"$work/chromium.log" 2>&1
check "QC page: Chromium renders a screenshot" test -s "$work/report.png"
check "QC page: no console message (script errors included)" test -z "$(grep CONSOLE "$work/chromium.log")"
grep CONSOLE "$work/chromium.log"
chromium --headless=new --no-sandbox --disable-gpu --dump-dom "file://$work/out/report.html" >"$work/dom.html" \
  2>/dev/null
check "QC page: the DOM holds the 7 rows" test "$(grep -o '<tr class=' "$work/dom.html" | wc -l)" -eq 7
if [ -n "${KEEP_SCREENSHOT:-}" ]; then cp "$work/report.png" "$KEEP_SCREENSHOT"; fi
check "QC page: figures are files beside it, each one there" "$python" - "$work/out/report.html" <<'PY'
import os, re, sys
page = open(sys.argv[1]).read()
sources = re.findall(r'<img src="([^"]+)"', page)
assert "data:" not in page and len(sources) == 3 * 6, sources  # 6 structures complete, 3 figures each
missing = [s for s in sources if not os.path.exists(os.path.join(os.path.dirname(sys.argv[1]), s))]
assert not missing, missing
PY
chromium --headless=new --no-sandbox --disable-gpu --dump-dom "file://$work/out/report.html#flagged" \
  >"$work/flagged.html" 2>/dev/null
check "QC page: #flagged shows the 3 flagged rows only" \
  test "$(grep -c '<tr class="flagged"' "$work/flagged.html")" -eq 3 -a \
  "$(grep -c '<tr class="" [^>]*hidden=""' "$work/flagged.html")" -eq 4
node "$here/check_qc_page.js" cohort "$work/out/report.html" "$work/view.png"
check "QC page in Chromium (Playwright): sorting, ratings and their export, the interactive view" test $? -eq 0
if [ -n "${KEEP_SCREENSHOT:-}" ]; then cp "$work/view.png" "${KEEP_SCREENSHOT%.png}_view.png"; fi

# A cohort's page: 500 segmentations (one job's files linked under 500
# subjects), every row present and no script error. Its load time is printed,
# not asserted (Ecosystem.md has the figure).
check "QC page of 500: written, every row complete" "$python" - "$WORKFLOWS" "$work/out" "$work/qc500" <<'PY'
import os, sys
sys.path.insert(0, sys.argv[1])
import dynsub_bids as bids, qc_report
source, out = sys.argv[2], sys.argv[3]
def job_of(subject, session=None, entities=""):
    return bids.Job([bids.Structure(subject, session, entities, "caudateL", f"sub-{subject}_T1w.nii.gz")])
def paths(out, job):
    """Every file of a one-structure job (its report is its structure's too)."""
    files = [bids.job_paths(out, job), bids.structure_paths(out, job.dir, job.stem, "caudateL"),
             bids.figure_paths(out, job.dir, job.stem, "caudateL")]
    return sorted({path for group in files for path in group.values()} |
                  {bids.view_path(out, job.dir, job.stem, job.desc)})
files = paths(source, job_of("03", "2", "_acq-hires_run-1"))  # the one-structure job of sub-03 ses-2
jobs = {}
for n in range(1000, 1500):
    job = job_of(str(n))
    for original, path in zip(files, paths(out, job)):
        os.makedirs(os.path.dirname(path), exist_ok=True)
        os.link(original, path)
    jobs[job.key] = job
rows = qc_report.write_report(jobs, out, f"{out}/report.html", os.environ["NIIVUE"])
assert len(rows) == 500 and all(r["status"] == "ok" for r in rows), "the page's rows are not all complete"
PY
start=$EPOCHREALTIME
chromium --headless=new --no-sandbox --disable-gpu --enable-logging=stderr --v=0 --dump-dom \
  "file://$work/qc500/report.html" >"$work/dom500.html" 2>"$work/chromium500.log"
echo "QC page of 500: $(du -k "$work/qc500/report.html" | cut -f1) kB; Chromium started, loaded it and wrote its" \
  "DOM in $(awk "BEGIN { print $EPOCHREALTIME - $start }") s"
check "QC page of 500: every row present" test "$(grep -o '<tr class=' "$work/dom500.html" | wc -l)" -eq 500
check "QC page of 500: no console message" test -z "$(grep CONSOLE "$work/chromium500.log")"
node "$here/check_qc_page.js" scale "$work/qc500/report.html" 500
check "QC page of 500 in Chromium (Playwright): every row, sorting, no script error" test $? -eq 0

# An image that loses a structure's landmarks: its job is regrouped, and
# what the earlier grouping wrote goes (the joint labelmap, the dropped
# structure's files), so the derivatives describe the dataset as it is.
rm "$work/bids/derivatives/landmarks/sub-02/anat/sub-02_desc-putamenL_landmarks.fcsv"
snake out="$work/out" --cores 2 >"$work/regroup.log" 2>&1
check "regrouped: exit 0" test $? -eq 0 || tail -20 "$work/regroup.log"
check "regrouped: the caudate alone has its own labelmap" \
  test -s "$work/out/sub-02/anat/sub-02_space-orig_desc-caudateL_dseg.nii.gz"
check "regrouped: the joint labelmap and the putamen's files are gone" \
  test -z "$(find "$work/out/sub-02" -name 'sub-02_space-orig_dseg*' -o -name '*putamenL*')"
check "regrouped: the derivatives keep the naming rules" \
  "$python" "$here/check_derivatives.py" "$work/bids" "$work/out" 3

snakemake -s "$WORKFLOWS/Snakefile" --cores 1 --config out="$work/x" >"$work/bad.log" 2>&1
check "no bids: exit non-zero" test $? -ne 0
check "no bids: says what is required" grep -q "config bids=DIR is required" "$work/bad.log"
snake out="$work/x" niivue="$work/none.js" --cores 1 >"$work/bad.log" 2>&1
check "missing NiiVue file: exit non-zero" test $? -ne 0
check "missing NiiVue file: named" grep -q "niivue=$work/none.js: no such file" "$work/bad.log"
check "missing NiiVue file: nothing written" test ! -e "$work/x"
mkdir -p "$work/bids/sub-05/anat" && cp "$work/bids/sub-01/anat/sub-01_T1w.nii.gz" \
  "$work/bids/sub-05/anat/sub-05_foo-1_T1w.nii.gz"
snake out="$work/out" --cores 1 >"$work/bad.log" 2>&1
check "unhandled T1w name: the others run on (exit 0)" test $? -eq 0
check "unhandled T1w name: skipped with a warning naming it" \
  grep -q "warning: .*sub-05_foo-1_T1w.nii.gz: skipped" "$work/bad.log"

echo "$failures failure(s)"
exit $((failures > 0))
