#!/usr/bin/env python3
"""A small BIDS cohort made from the Colin27 MRI and its AAL atlas, for testing
the workflow:

    make_cohort.py TEMPLATES DATA DIR [--broken]

  sub-01          Colin27 at 1 mm; left caudate and putamen landmarks
                  (.mrk.json, LPS) and a seed click in the left thalamus
                  (seeds.tsv): one job for the three; AAL reference
  sub-02          the same MRI moved by a rigid transform (12 degrees about an
                  oblique axis, then 5, -8, 3 mm): its caudate and putamen
                  landmarks (.fcsv, in RAS) and its AAL reference move with it
  sub-03/ses-2    the 0.5 mm Colin27 (another grid, no reference), its name with
                  entities (acq-hires_run-1) that its outputs' names carry;
                  landmarks as CSV, named without them
  --broken adds only sub-04 to an existing cohort: its T1w is a truncated
  gzip file (the other subjects' files are left as they are).

DATA is the project's Data directory (the demo's caudate and putamen landmarks). Uses
nibabel and numpy (Debian python3-nibabel).
"""
import json
import math
import os
import shutil
import sys

import nibabel
import numpy

LPS = numpy.diag([-1.0, -1.0, 1.0, 1.0])  # RAS <-> LPS


def rigid():
    """Rotation by 12 degrees about the unit axis (1, 2, 2)/3, then a shift, in LPS mm."""
    axis = numpy.array([1.0, 2.0, 2.0]) / 3.0
    angle = math.radians(12.0)
    k = numpy.array([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]])
    transform = numpy.eye(4)
    transform[:3, :3] = numpy.eye(3) + math.sin(angle) * k + (1 - math.cos(angle)) * k @ k
    transform[:3, 3] = [5.0, -8.0, 3.0]
    return transform


def save_moved(source, target, transform_lps):
    """The same voxels, placed by transform_lps (LPS) after the source's own placement."""
    image = nibabel.load(source)
    affine = LPS @ transform_lps @ LPS @ image.affine
    moved = nibabel.Nifti1Image(numpy.asanyarray(image.dataobj), affine, image.header)
    moved.set_qform(affine, code=1)
    moved.set_sform(affine, code=1)
    nibabel.save(moved, target)


def landmarks(path):
    data = json.load(open(path))
    return [p["position"] for p in data["markups"][0]["controlPoints"]]


def write_mrk(points, path):
    json.dump({"@schema": "https://raw.githubusercontent.com/slicer/slicer/master/Modules/Loadable/Markups/"
                          "Resources/Schema/markups-schema-v1.0.3.json#",
               "markups": [{"type": "Fiducial", "coordinateSystem": "LPS", "coordinateUnits": "mm",
                            "controlPoints": [{"id": str(i + 1), "label": f"P-{i + 1}", "position": list(p),
                                               "positionStatus": "defined"} for i, p in enumerate(points)]}]},
              open(path, "w"), indent=1)


def write_fcsv_ras(points, path):
    with open(path, "w") as f:
        f.write("# Markups fiducial file version = 4.13\n# CoordinateSystem = RAS\n"
                "# columns = id,x,y,z,ow,ox,oy,oz,vis,sel,lock,label,desc,associatedNodeID\n")
        for i, (x, y, z) in enumerate(points):
            f.write(f"{i + 1},{-x!r},{-y!r},{z!r},0,0,0,1,1,1,0,P-{i + 1},,\n")


def write_csv(points, path):
    with open(path, "w") as f:
        f.write("label,x,y,z\n")
        for i, (x, y, z) in enumerate(points):
            f.write(f"P-{i + 1},{x!r},{y!r},{z!r}\n")


def anat(root, subject, session=None):
    path = f"{root}/sub-{subject}" + (f"/ses-{session}" if session else "") + "/anat"
    os.makedirs(path, exist_ok=True)
    return path


def main():
    if len(sys.argv) not in (4, 5) or (len(sys.argv) == 5 and sys.argv[4] != "--broken"):
        sys.exit(__doc__)
    templates, data, root = sys.argv[1:4]
    caudate = landmarks(f"{data}/Landmarks/caudate_left.mrk.json")
    marks = f"{root}/derivatives/landmarks"
    if len(sys.argv) == 5:
        whole = open(f"{templates}/ch2.nii.gz", "rb").read()
        open(f"{anat(root, '04')}/sub-04_T1w.nii.gz", "wb").write(whole[: len(whole) // 3])
        write_mrk(caudate, f"{anat(marks, '04')}/sub-04_desc-caudateL_landmarks.mrk.json")
        return
    os.makedirs(root, exist_ok=True)
    json.dump({"Name": "DynSub test cohort (Colin27)", "BIDSVersion": "1.9.0", "DatasetType": "raw"},
              open(f"{root}/dataset_description.json", "w"), indent=2)
    reference = f"{root}/derivatives/reference"
    with open(f"{root}/participants.tsv", "w") as f:
        f.write("participant_id\nsub-01\nsub-02\nsub-03\n")

    shutil.copy(f"{templates}/ch2.nii.gz", f"{anat(root, '01')}/sub-01_T1w.nii.gz")
    write_mrk(caudate, f"{anat(marks, '01')}/sub-01_desc-caudateL_landmarks.mrk.json")
    putamen = landmarks(f"{data}/Landmarks/putamen_left.mrk.json")
    write_mrk(putamen, f"{anat(marks, '01')}/sub-01_desc-putamenL_landmarks.mrk.json")
    shutil.copy(f"{templates}/aal.nii.gz", f"{anat(reference, '01')}/sub-01_dseg.nii.gz")
    # A click inside the left thalamus (AAL 77): its voxel nearest the label's centroid.
    aal = nibabel.load(f"{templates}/aal.nii.gz")
    voxels = numpy.argwhere(numpy.asanyarray(aal.dataobj) == 77)
    inside = voxels[numpy.argmin(numpy.linalg.norm(voxels - voxels.mean(axis=0), axis=1))]
    click = (LPS @ aal.affine @ numpy.append(inside, 1.0))[:3]
    with open(f"{root}/derivatives/seeds.tsv", "w") as f:
        f.write("participant_id\tsession_id\tstructure\tx\ty\tz\n")
        f.write("sub-01\tn/a\tthalamusL\t%r\t%r\t%r\n" % tuple(float(v) for v in click))
    with open(f"{reference}/dseg.tsv", "w") as f:
        f.write("index\tname\n71\tcaudateL\n73\tputamenL\n77\tthalamusL\n")

    transform = rigid()
    save_moved(f"{templates}/ch2.nii.gz", f"{anat(root, '02')}/sub-02_T1w.nii.gz", transform)
    save_moved(f"{templates}/aal.nii.gz", f"{anat(reference, '02')}/sub-02_dseg.nii.gz", transform)
    for structure, points in (("caudateL", caudate), ("putamenL", putamen)):
        moved = [(transform @ numpy.append(p, 1.0))[:3].tolist() for p in points]
        write_fcsv_ras(moved, f"{anat(marks, '02')}/sub-02_desc-{structure}_landmarks.fcsv")

    shutil.copy(f"{templates}/ch2better.nii.gz", f"{anat(root, '03', '2')}/sub-03_ses-2_acq-hires_run-1_T1w.nii.gz")
    write_csv(caudate, f"{anat(marks, '03', '2')}/sub-03_ses-2_desc-caudateL_landmarks.csv")


if __name__ == "__main__":
    main()
