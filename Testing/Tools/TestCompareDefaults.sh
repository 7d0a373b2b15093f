#!/usr/bin/env bash
# Tools/compare_defaults.py on a one-run plan (the defaults_plan's first
# single-scan tuning subject, its left caudate, six slices of clicks): each
# setting gives one line per group with its change from the defaults, a
# setting known to cost the caudate (no slice-end march: 0.75 -> 0.46 on the
# single-scan tuning subjects) shows a loss, and a malformed setting is refused.
# Usage: TestCompareDefaults.sh TOOLS_DIR DATA_DIR DYNSUB
set -u
tools=$1 data=$2 dynsub=$3
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
/usr/bin/python3 - "$data/Evaluation/defaults_plan.json" "$work/plan.json" <<'PY'
import json, sys
plan = json.load(open(sys.argv[1]))
plan["cohorts"] = [dict(plan["cohorts"][0], subjects={"tuning": [1], "test": [101]})]
plan["structures"] = [s for s in plan["structures"] if s["name"] == "caudate_left"]
plan["protocols"] = plan["protocols"][:1]
json.dump(plan, open(sys.argv[2], "w"))
PY
out=$(/usr/bin/python3 "$tools/compare_defaults.py" --plan "$work/plan.json" --out "$work/out" --dynsub "$dynsub" \
  'no_ends={"slice_ends": false}') || { echo "FAIL: the sweep did not run"; exit 1; }
echo "$out"
status=0
[ "$(echo "$out" | grep -c 'single_scan')" -eq 2 ] || { echo "FAIL: expected two lines for single_scan"; status=1; }
echo "$out" | grep -q '^defaults .*(+0.000)' || { echo "FAIL: the defaults' line"; status=1; }
echo "$out" | grep -q '^no_ends .*(-0\.' || { echo "FAIL: no slice ends should cost the caudate"; status=1; }
if /usr/bin/python3 "$tools/compare_defaults.py" --plan "$work/plan.json" --out "$work/out" 'bad={' 2>"$work/err"; then
  echo "FAIL: a malformed setting was accepted"; status=1
fi
grep -q "bad={: not NAME=JSON" "$work/err" || { echo "FAIL: the malformed setting's error"; cat "$work/err"; status=1; }
exit $status
