#!/usr/bin/env python3
"""Write a NIfTI image as NRRD the way 3D Slicer stores volumes.

    nifti_to_nrrd.py IN.nii[.gz] OUT.nrrd

NRRD keeps the geometry in LPS ("space: left-posterior-superior"); NIfTI's
affine is RAS, so its first two rows are negated. The data is written
gzip-compressed in the file's own voxel type (or float32 when the NIfTI
header scales the values). Uses nibabel and numpy (Debian python3-nibabel).
"""
import gzip
import sys

import nibabel
import numpy


NRRD_TYPES = {"uint8": "uint8", "int8": "int8", "uint16": "uint16", "int16": "int16",
              "uint32": "uint32", "int32": "int32", "float32": "float", "float64": "double"}


def main():
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    source, target = sys.argv[1], sys.argv[2]
    image = nibabel.load(source)
    if len(image.shape) != 3:
        sys.exit(f"{source}: not a 3D image")
    scaled = image.dataobj.slope not in (None, 1) or image.dataobj.inter not in (None, 0)
    data = numpy.asarray(image.get_fdata(dtype=numpy.float32) if scaled else numpy.asanyarray(image.dataobj))
    if data.dtype.name not in NRRD_TYPES:
        sys.exit(f"{source}: voxel type {data.dtype} is not handled")
    lps = numpy.diag([-1.0, -1.0, 1.0]) @ image.affine[:3, :]
    directions = " ".join("(" + ",".join(repr(float(v)) for v in lps[:, axis]) + ")" for axis in range(3))
    origin = "(" + ",".join(repr(float(v)) for v in lps[:, 3]) + ")"
    header = (
        "NRRD0004\n"
        f"type: {NRRD_TYPES[data.dtype.name]}\n"
        "dimension: 3\n"
        "space: left-posterior-superior\n"
        f"sizes: {' '.join(str(n) for n in data.shape)}\n"
        f"space directions: {directions}\n"
        "kinds: domain domain domain\n"
        "endian: little\n"
        "encoding: gzip\n"
        f"space origin: {origin}\n\n"
    )
    # NRRD's first axis varies fastest, as NIfTI's does: Fortran order.
    raw = numpy.asarray(data, dtype=data.dtype.newbyteorder("<")).tobytes(order="F")
    with open(target, "wb") as out:
        out.write(header.encode("ascii"))
        out.write(gzip.compress(raw, compresslevel=1))


if __name__ == "__main__":
    main()
