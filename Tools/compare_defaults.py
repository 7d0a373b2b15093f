#!/usr/bin/env python3
"""Whether a segmentation default holds across subject groups: runs a plan's
tuning split once per setting (its "segment" object replaced by the
setting's) and prints, per group of subjects (a cohort, or an image), the
mean Dice over every run and the worst subject's mean, beside the same for
the defaults. A failed run counts as Dice 0.

    Tools/compare_defaults.py [--plan PLAN] [--out DIR] [--dynsub EXE] NAME=JSON ...

NAME=JSON names a setting and gives the plan's "segment" object for it, e.g.
    sigma_07='{"sigma_mm": 0.7}'  no_ends='{"slice_ends": false}'
The defaults ("{}") always run first. The plan defaults to
Data/Evaluation/defaults_plan.json (the single-scan and synthesized tuning
subjects, every structure, three click protocols). A setting whose DIR/NAME
holds a runs.csv is not run again, so a sweep can be extended.
"""
import argparse
import csv
import json
import os
import statistics
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def summarize(runs_csv):
    """{group: (mean Dice, worst subject's mean Dice, failed runs)}."""
    groups = {}
    for row in csv.DictReader(open(runs_csv)):
        dice = float(row["dice"]) if row["dice"] not in ("", "nan") and not row["error"] else 0.0
        subjects = groups.setdefault(row["image"], {})
        subjects.setdefault(row["subject"] or row["image"], []).append((dice, bool(row["error"])))
    summary = {}
    for group, subjects in groups.items():
        runs = [run for values in subjects.values() for run in values]
        summary[group] = (statistics.mean(d for d, _ in runs),
                          min(statistics.mean(d for d, _ in values) for values in subjects.values()),
                          sum(failed for _, failed in runs))
    return summary


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("settings", nargs="*", help="NAME=JSON: the plan's segment object for one setting")
    parser.add_argument("--plan", default=os.path.join(ROOT, "Data/Evaluation/defaults_plan.json"))
    parser.add_argument("--out", default="results/defaults")
    parser.add_argument("--dynsub", default=os.path.join(ROOT, "build/bin/dynsub"))
    args = parser.parse_args()
    settings = [("defaults", {})]
    for text in args.settings:
        name, _, value = text.partition("=")
        try:
            segment = json.loads(value)
        except json.JSONDecodeError as error:
            sys.exit(f"compare_defaults: {text}: not NAME=JSON ({error})")
        if not name or not isinstance(segment, dict):
            sys.exit(f"compare_defaults: {text}: expected NAME={{...}}")
        settings.append((name, segment))
    plan = json.load(open(args.plan))
    os.makedirs(args.out, exist_ok=True)
    baseline = None
    for name, segment in settings:
        directory = os.path.join(args.out, name)
        runs_csv = os.path.join(directory, "runs.csv")
        if not os.path.exists(runs_csv):
            setting_plan = dict(plan, segment=segment)
            plan_path = os.path.join(args.out, name + ".json")
            with open(plan_path, "w") as f:
                json.dump(setting_plan, f, indent=1)
            subprocess.run([args.dynsub, "evaluate", plan_path, "--split", "tuning", "--out", directory],
                           stdout=subprocess.DEVNULL, check=True)
        summary = summarize(runs_csv)
        baseline = baseline or summary
        cells = []
        for group, (mean, worst, failed) in sorted(summary.items()):
            change = mean - baseline[group][0]
            cells.append(f"{group} {mean:.3f} ({change:+.3f}), worst subject {worst:.3f}"
                         + (f", {failed} failed" if failed else ""))
        print(f"{name:16s} " + "; ".join(cells), flush=True)


if __name__ == "__main__":
    main()
