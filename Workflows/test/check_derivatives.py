#!/usr/bin/env python3
"""Checks a DynSub derivative dataset against the BIDS naming rules it claims.

    check_derivatives.py RAW DERIVATIVES EXPECTED_JOBS

RAW is the input dataset: every file the workflow read (T1w images) must be
valid BIDS by the BIDS validator (Debian python3-bids-validator). In
DERIVATIVES, every file must be one of: dataset_description.json (with
DatasetType derivative and GeneratedBy), the group table and its sidecar,
job logs, the BIDS App's work/ folder, or per-subject files named
sub-<label>[_ses-<label>][entities]_space-orig[_desc-<label>]_<suffix> in sub-<label>/[ses-<label>/]anat
(entities: the T1w's own acq-, ce-, rec-, run-, echo-, part-, in that order,
its SpatialReference that T1w)
(figures: ..._desc-<label>_<figure>.png and ..._[desc-<label>_]view.js in
.../figures), with entities in BIDS order, labels of letters and digits,
folders matching the entities, every dseg.nii.gz with its .tsv lookup table
(index, name, color) and .json sidecar, on the grid of its T1w, holding
every value the table names and no other: a dseg with desc- holds that one
structure, one without holds several, each with its own surface and report.
EXPECTED_JOBS is the number of dseg files (jobs) that must be there.
"""
import csv
import json
import os
import re
import sys

import nibabel
import numpy
from bids_validator import BIDSValidator

L = r"[A-Za-z0-9]+"
# The entities an anatomical image's name may carry after sub- and ses-, in
# the specification's order.
SUBJECT = rf"^(?P<stem>sub-(?P<sub>{L})(?:_ses-(?P<ses>{L}))?" + "".join(
    rf"(?:_{e}-{L})?" for e in ("acq", "ce", "rec", "run", "echo", "part")) + ")"
ANAT = re.compile(rf"{SUBJECT}_space-orig(?:_desc-(?P<desc>{L}))?_"
                  r"(?P<suffix>dseg\.nii\.gz|dseg\.tsv|dseg\.json|surface\.vtp|report\.json|convergence\.csv)$")
FIGURE = re.compile(rf"{SUBJECT}(?:_desc-(?P<desc>{L})_"
                    rf"(?P<suffix>(?:slices|surface3d|convergence)\.png|view\.js)|_(?P<view>view\.js))$")
LOG = re.compile(rf"{SUBJECT}(?:_desc-(?P<desc>{L}))?\.log$")
problems = []


def fail(message):
    problems.append(message)


def main():
    raw, out, expected = sys.argv[1], sys.argv[2], int(sys.argv[3])
    validator = BIDSValidator()
    for folder, _, files in os.walk(raw):
        if "/derivatives" in folder.removeprefix(raw):
            continue
        for name in files:
            path = "/" + os.path.relpath(os.path.join(folder, name), raw)
            if name.endswith("_T1w.nii.gz") and not validator.is_bids(path):
                fail(f"raw: {path} is not valid BIDS")

    description = json.load(open(f"{out}/dataset_description.json"))
    if description.get("DatasetType") != "derivative":
        fail("dataset_description.json: DatasetType is not derivative")
    generated = description.get("GeneratedBy") or [{}]
    if not (generated[0].get("Name") and generated[0].get("Version")):
        fail("dataset_description.json: GeneratedBy needs Name and Version")
    if not description.get("BIDSVersion"):
        fail("dataset_description.json: no BIDSVersion")

    segmentations = 0
    for folder, dirs, files in os.walk(out):
        dirs[:] = [d for d in dirs if not d.startswith(".")]  # .snakemake is Snakemake's own
        relative = os.path.relpath(folder, out)
        for name in files:
            path = os.path.join(relative, name)
            if relative == "." and name in ("dataset_description.json", "segmentations.tsv", "segmentations.json",
                                            "report.html", ".bidsignore"):
                continue
            parts = relative.split(os.sep)
            if parts[0] == "work":  # the BIDS App's Snakemake bookkeeping and cluster logs
                continue
            if path == os.path.join("viewer", "niivue.umd.js"):  # the QC page's viewer
                continue
            if parts[0] == "logs":
                match, parts = LOG.match(name), parts[1:]
                kind = None
            elif parts[-1] == "anat":
                match, kind = ANAT.match(name), "anat"
                parts = parts[:-1]
            elif parts[-1] == "figures":
                match, kind = FIGURE.match(name), "figures"
                parts = parts[:-1]
            else:
                match = None
            if not match:
                fail(f"{path}: not a BIDS derivative name this workflow writes")
                continue
            folders = [f"sub-{match['sub']}"] + ([f"ses-{match['ses']}"] if match["ses"] else [])
            if parts != folders:
                fail(f"{path}: its folder does not match its entities {folders}")
            if kind == "anat" and not match["desc"] and match["suffix"] in ("surface.vtp", "convergence.csv"):
                fail(f"{path}: a structure's own file without its desc-")
            if kind == "anat" and match["suffix"] == "dseg.nii.gz":
                segmentations += 1
                check_dseg(raw, os.path.join(folder, name), match)
    if segmentations != expected:
        fail(f"{segmentations} segmentations, expected {expected}")
    for problem in problems:
        print("FAIL:", problem)
    print(f"{segmentations} segmentations checked, {len(problems)} problem(s)")
    sys.exit(1 if problems else 0)


def check_dseg(raw, path, match):
    stem = path.removesuffix(".nii.gz")
    for companion in (stem + ".tsv", stem + ".json"):
        if not os.path.exists(companion):
            fail(f"{path}: no {os.path.basename(companion)} beside it")
            return
    table = list(csv.DictReader(open(stem + ".tsv"), delimiter="\t"))
    names = [r["name"] for r in table]
    if [list(r.keys()) for r in table][:1] != [["index", "name", "color"]] or \
            (match["desc"] and names != [match["desc"]]) or (not match["desc"] and len(names) < 2):
        fail(f"{stem}.tsv: expected columns index, name, color and "
             + (f"one row naming {match['desc']}" if match["desc"] else "a row per structure, two or more"))
        return
    sidecar = json.load(open(stem + ".json"))
    for key in ("Sources", "SpatialReference", "Report", "Structures"):
        if key not in sidecar:
            fail(f"{stem}.json: no {key}")
    folder = os.path.dirname(path)
    for structure in sidecar.get("Structures", []):
        for key in ("Surface", "Report", "Convergence"):
            if not os.path.exists(os.path.join(folder, structure.get(key, "?"))):
                fail(f"{stem}.json: {structure.get('Name')}'s {key} {structure.get(key)} is not beside it")
    if [s.get("Name") for s in sidecar.get("Structures", [])] != names:
        fail(f"{stem}.json: its Structures are not the table's {names}")
    source = sidecar.get("SpatialReference", "").removeprefix("bids:raw:")
    if not re.match(rf"{re.escape(match['stem'])}_T1w\.nii(\.gz)?$", os.path.basename(source)):
        fail(f"{path}: its SpatialReference {source} is not the T1w its name carries ({match['stem']}_T1w)")
    t1w = nibabel.load(os.path.join(raw, source))
    labels = nibabel.load(path)
    if labels.shape != t1w.shape or not numpy.allclose(labels.affine, t1w.affine, atol=1e-4):
        fail(f"{path}: not on the grid of {source}")
    values = set(numpy.unique(numpy.asanyarray(labels.dataobj)).tolist())
    if values != {0} | {int(r["index"]) for r in table}:
        fail(f"{path}: values {values}, its table names {[r['index'] for r in table]}")


if __name__ == "__main__":
    main()
