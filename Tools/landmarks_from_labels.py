#!/usr/bin/env python3
"""Simulate an expert placing landmarks on a structure's boundary, slice by slice.

    landmarks_from_labels.py LABELS.nii.gz LABEL[,LABEL...] AXIS SLICES PER_SLICE OUT.mrk.json

LABELS is a NIfTI labelmap drawn by an expert (e.g. the AAL atlas). AXIS is
sagittal, coronal or axial (the voxel axes i, j, k of the file, which for
the MNI-grid files of mricron-data are x, y, z). SLICES slices are taken
evenly across the structure's extent, at the centres of SLICES equal parts;
on each, the boundary of the structure (the midpoints between a voxel of the
structure and an in-slice 4-neighbour outside it) is sampled at PER_SLICE
points by farthest-point sampling, starting from the boundary point furthest
from the slice's centroid. The points are written as a 3D Slicer markups file
in LPS mm (the file's sform, RAS, with x and y negated).

Only the Python standard library is used.
"""
import gzip
import json
import struct
import sys


def read_nifti(path):
    data = gzip.open(path).read() if path.endswith(".gz") else open(path, "rb").read()
    if struct.unpack_from("<i", data, 0)[0] != 348:
        sys.exit(f"{path}: not a little-endian NIfTI-1 file")
    dims = struct.unpack_from("<8h", data, 40)
    datatype = struct.unpack_from("<h", data, 70)[0]
    offset = int(struct.unpack_from("<f", data, 108)[0])
    sform = [struct.unpack_from("<4f", data, 280 + 16 * r) for r in range(3)]
    size = dims[1:4]
    count = size[0] * size[1] * size[2]
    formats = {2: "B", 4: "h", 8: "i", 16: "f", 512: "H"}
    if datatype not in formats:
        sys.exit(f"{path}: unsupported NIfTI datatype {datatype}")
    voxels = struct.unpack_from(f"<{count}{formats[datatype]}", data, offset)
    return size, sform, voxels


def main():
    if len(sys.argv) != 7:
        sys.exit(__doc__)
    path, labels, axis_name, slices, per_slice, out = sys.argv[1:]
    labels = {int(v) for v in labels.split(",")}
    axis = {"sagittal": 0, "coronal": 1, "axial": 2}[axis_name]
    slices, per_slice = int(slices), int(per_slice)
    size, sform, voxels = read_nifti(path)

    def inside(i, j, k):
        if not (0 <= i < size[0] and 0 <= j < size[1] and 0 <= k < size[2]):
            return False
        return voxels[i + size[0] * (j + size[1] * k)] in labels

    def lps(index):
        ras = [sum(sform[r][c] * index[c] for c in range(3)) + sform[r][3] for r in range(3)]
        return [-ras[0], -ras[1], ras[2]]

    # The structure's extent along the axis.
    extent = set()
    for k in range(size[2]):
        for j in range(size[1]):
            for i in range(size[0]):
                if voxels[i + size[0] * (j + size[1] * k)] in labels:
                    extent.add((i, j, k)[axis])
    if not extent:
        sys.exit(f"{path}: no voxel has label(s) {sorted(labels)}")
    first, last = min(extent), max(extent)
    chosen = [round(first + (last - first) * (s + 0.5) / slices) for s in range(slices)]

    others = [a for a in range(3) if a != axis]
    points = []
    for n in chosen:
        boundary = []
        for v in range(size[others[1]]):
            for u in range(size[others[0]]):
                index = [0, 0, 0]
                index[axis], index[others[0]], index[others[1]] = n, u, v
                if not inside(*index):
                    continue
                for du, dv in [(1, 0), (-1, 0), (0, 1), (0, -1)]:
                    neighbour = list(index)
                    neighbour[others[0]] += du
                    neighbour[others[1]] += dv
                    if not inside(*neighbour):
                        boundary.append([(index[a] + neighbour[a]) / 2 for a in range(3)])
        if not boundary:
            continue
        centroid = [sum(p[a] for p in boundary) / len(boundary) for a in range(3)]
        dist2 = lambda p, q: sum((p[a] - q[a]) ** 2 for a in range(3))
        picked = [max(boundary, key=lambda p: dist2(p, centroid))]
        while len(picked) < min(per_slice, len(boundary)):
            picked.append(max(boundary, key=lambda p: min(dist2(p, q) for q in picked)))
        points += picked

    control_points = [{"id": str(n + 1), "label": f"P-{n + 1}", "position": lps(p), "positionStatus": "defined"}
                      for n, p in enumerate(points)]
    document = {"@schema": "https://raw.githubusercontent.com/slicer/slicer/master/Modules/Loadable/Markups/"
                           "Resources/Schema/markups-schema-v1.0.3.json#",
                "markups": [{"type": "Fiducial", "coordinateSystem": "LPS", "coordinateUnits": "mm",
                             "controlPoints": control_points}]}
    with open(out, "w") as f:
        json.dump(document, f, indent=2)
        f.write("\n")
    print(f"{len(points)} points on {axis_name} slices {chosen} (voxel index) written to {out}")


if __name__ == "__main__":
    main()
