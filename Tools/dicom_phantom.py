#!/usr/bin/env python3
"""A ball phantom on an oblique, anisotropic grid, written three ways for the
DICOM checks (Applications/dynsub/test/TestDicom.sh):

  OUT/series/slice_NNN.dcm  the image as a DICOM MR series, one file per slice,
                            made by DCMTK's dump2dcm (a writer DynSub does not use),
                            each with a sequence of undefined length (a
                            referenced image) before its pixels;
  OUT/phantom.nii.gz        the same image as NIfTI (sform and qform);
  OUT/ball.nii.gz           the analytic ball as a labelmap (1 where a voxel
                            centre lies inside it) on the same grid;
  OUT/ball.csv              26 points on the ball (x,y,z LPS mm): the 6 axis,
                            8 corner and 12 edge directions of a cube.

The grid: 48 x 40 x 32 voxels of 0.75 x 0.8 x 1.5 mm, its axes turned about
two LPS axes, origin (-20.5, 10.25, 5). The ball: radius 9 mm, centre at the
middle of the grid. Intensity 1000 inside, 200 outside, a 1 mm blurred edge,
and +-30 of deterministic noise. Prints "CX,CY,CZ" of the centre (LPS mm).

Usage: dicom_phantom.py OUT       (needs dump2dcm, Debian package dcmtk)
"""
import gzip
import math
import os
import struct
import subprocess
import sys

SIZE = (48, 40, 32)
SPACING = (0.75, 0.8, 1.5)
ORIGIN = (-20.5, 10.25, 5.0)
RADIUS = 9.0


def matmul(a, b):
    return [[sum(a[r][k] * b[k][c] for k in range(3)) for c in range(3)] for r in range(3)]


# Columns: the i, j, k axes in LPS. A turn about z (cos 0.6, sin 0.8), then about x (0.8, 0.6).
ROT_Z = [[0.6, -0.8, 0.0], [0.8, 0.6, 0.0], [0.0, 0.0, 1.0]]
ROT_X = [[1.0, 0.0, 0.0], [0.0, 0.8, -0.6], [0.0, 0.6, 0.8]]
DIRECTION = matmul(ROT_Z, ROT_X)


def physical(i, j, k):
    index = (i * SPACING[0], j * SPACING[1], k * SPACING[2])
    return [ORIGIN[r] + sum(DIRECTION[r][a] * index[a] for a in range(3)) for r in range(3)]


CENTRE = physical((SIZE[0] - 1) / 2, (SIZE[1] - 1) / 2, (SIZE[2] - 1) / 2)


def volumes():
    seed = 12345
    image, labels = [], []
    for k in range(SIZE[2]):
        for j in range(SIZE[1]):
            for i in range(SIZE[0]):
                r = math.dist(physical(i, j, k), CENTRE)
                seed = (1103515245 * seed + 12345) % 2**31
                noise = (seed % 61) - 30
                image.append(int(round(200 + 800 * 0.5 * (1 - math.tanh((r - RADIUS) / 0.5)) + noise)))
                labels.append(1 if r <= RADIUS else 0)
    return image, labels


def quaternion(m):
    """(b, c, d) of the unit quaternion of a proper rotation, a >= 0 (Shepperd's method)."""
    trace = m[0][0] + m[1][1] + m[2][2]
    if trace > 0:
        s = 2 * math.sqrt(1 + trace)
        q = (0.25 * s, (m[2][1] - m[1][2]) / s, (m[0][2] - m[2][0]) / s, (m[1][0] - m[0][1]) / s)
    elif m[0][0] > m[1][1] and m[0][0] > m[2][2]:
        s = 2 * math.sqrt(1 + m[0][0] - m[1][1] - m[2][2])
        q = ((m[2][1] - m[1][2]) / s, 0.25 * s, (m[0][1] + m[1][0]) / s, (m[0][2] + m[2][0]) / s)
    elif m[1][1] > m[2][2]:
        s = 2 * math.sqrt(1 + m[1][1] - m[0][0] - m[2][2])
        q = ((m[0][2] - m[2][0]) / s, (m[0][1] + m[1][0]) / s, 0.25 * s, (m[1][2] + m[2][1]) / s)
    else:
        s = 2 * math.sqrt(1 + m[2][2] - m[0][0] - m[1][1])
        q = ((m[1][0] - m[0][1]) / s, (m[0][2] + m[2][0]) / s, (m[1][2] + m[2][1]) / s, 0.25 * s)
    sign = -1 if q[0] < 0 else 1
    return tuple(sign * x for x in q[1:])


def write_nifti(path, voxels, datatype, bitpix, pack):
    """NIfTI-1 with sform and qform (RAS = diag(-1, -1, 1) LPS)."""
    flip = (-1.0, -1.0, 1.0)
    rotation = [[flip[r] * DIRECTION[r][c] for c in range(3)] for r in range(3)]
    sform = [[rotation[r][c] * SPACING[c] for c in range(3)] + [flip[r] * ORIGIN[r]] for r in range(3)]
    b, c, d = quaternion(rotation)
    header = bytearray(348)
    struct.pack_into("<i", header, 0, 348)
    struct.pack_into("<8h", header, 40, 3, *SIZE, 1, 1, 1, 1)
    struct.pack_into("<hh", header, 70, datatype, bitpix)
    struct.pack_into("<8f", header, 76, 1.0, *SPACING, 1.0, 1.0, 1.0, 1.0)
    struct.pack_into("<f", header, 108, 352.0)  # vox_offset
    struct.pack_into("<f", header, 112, 1.0)  # scl_slope
    header[123] = 2 | 8  # xyzt_units: mm, s
    struct.pack_into("<hh", header, 252, 1, 1)  # qform_code, sform_code: scanner
    struct.pack_into("<6f", header, 256, b, c, d, *[flip[r] * ORIGIN[r] for r in range(3)])
    for r in range(3):
        struct.pack_into("<4f", header, 280 + 16 * r, *sform[r])
    header[344:348] = b"n+1\0"
    with gzip.open(path, "wb") as out:
        out.write(bytes(header) + bytes(4) + b"".join(pack(v) for v in voxels))


def ds(values):
    return "\\".join(f"{v:.6f}".rstrip("0").rstrip(".") for v in values)


def write_series(directory, image):
    os.makedirs(directory, exist_ok=True)
    root = "1.2.826.0.1.3680043.10.1347"  # DynSub's test phantoms
    study, series, frame = root + ".1", root + ".2", root + ".3"
    slice_voxels = SIZE[0] * SIZE[1]
    row = [DIRECTION[r][0] for r in range(3)]  # along a row: the i axis
    column = [DIRECTION[r][1] for r in range(3)]  # down a column: the j axis
    for k in range(SIZE[2]):
        pixels = os.path.join(directory, f"slice_{k:03d}.raw")
        with open(pixels, "wb") as out:
            out.write(struct.pack(f"<{slice_voxels}H", *image[k * slice_voxels:(k + 1) * slice_voxels]))
        dump = os.path.join(directory, f"slice_{k:03d}.dump")
        with open(dump, "w") as out:
            out.write(f"""(0008,0016) UI =MRImageStorage
(0008,0018) UI [{root}.4.{k + 1}]
(0008,0060) CS [MR]
(0008,1140) SQ (Sequence with undefined length #=1)
  (fffe,e000) na (Item with undefined length #=2)
    (0008,1150) UI =MRImageStorage
    (0008,1155) UI [{root}.4.{(k + 1) % SIZE[2] + 1}]
  (fffe,e00d) na (ItemDelimitationItem)
(fffe,e0dd) na (SequenceDelimitationItem)
(0010,0010) PN [Phantom^Ball]
(0010,0020) LO [BALL1]
(0020,000d) UI [{study}]
(0020,000e) UI [{series}]
(0020,0052) UI [{frame}]
(0020,0011) IS [1]
(0020,0013) IS [{k + 1}]
(0020,0032) DS [{ds(physical(0, 0, k))}]
(0020,0037) DS [{ds(row + column)}]
(0018,0050) DS [{ds([SPACING[2]])}]
(0028,0002) US 1
(0028,0004) CS [MONOCHROME2]
(0028,0010) US {SIZE[1]}
(0028,0011) US {SIZE[0]}
(0028,0030) DS [{ds([SPACING[1], SPACING[0]])}]
(0028,0100) US 16
(0028,0101) US 16
(0028,0102) US 15
(0028,0103) US 0
(7fe0,0010) OW ={pixels}
""")
        # Undefined lengths for the sequence and its item, as scanners often write them.
        subprocess.run(["dump2dcm", "--quiet", "--length-undefined", dump,
                        os.path.join(directory, f"slice_{k:03d}.dcm")], check=True)
        os.remove(pixels)
        os.remove(dump)


def main():
    if len(sys.argv) != 2:
        raise SystemExit(__doc__)
    out = sys.argv[1]
    image, labels = volumes()
    write_series(os.path.join(out, "series"), image)
    write_nifti(os.path.join(out, "phantom.nii.gz"), image, 512, 16, lambda v: struct.pack("<H", v))
    write_nifti(os.path.join(out, "ball.nii.gz"), labels, 2, 8, lambda v: struct.pack("<B", v))
    with open(os.path.join(out, "ball.csv"), "w") as points:
        points.write("x,y,z\n")
        for u in ((x, y, z) for x in (-1, 0, 1) for y in (-1, 0, 1) for z in (-1, 0, 1) if (x, y, z) != (0, 0, 0)):
            n = math.sqrt(sum(c * c for c in u))
            points.write(",".join(f"{CENTRE[r] + RADIUS * u[r] / n:.4f}" for r in range(3)) + "\n")
    print(",".join(f"{c:.4f}" for c in CENTRE))


if __name__ == "__main__":
    main()
