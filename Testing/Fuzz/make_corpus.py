#!/usr/bin/env python3
"""Writes the seed corpora of the fuzz targets into Corpus/<Target>/: small
files of every format each target reads, from Data/ and made here (standard
library only; DICOM slices by Tools/dicom_phantom.py, which needs dcmtk).
Run by hand when a format is added; the corpora are kept in the repository.

Usage: make_corpus.py [OUT]   (default: Corpus next to this script)
"""
import gzip
import os
import shutil
import struct
import subprocess
import sys
import tempfile
import zlib

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
DATA = os.path.join(ROOT, "Data")


def write(out, target, name, content):
    os.makedirs(os.path.join(out, target), exist_ok=True)
    with open(os.path.join(out, target, name), "wb") as f:
        f.write(content if isinstance(content, bytes) else content.encode())


def copy(out, target, *relative):
    with open(os.path.join(DATA, *relative), "rb") as f:
        write(out, target, os.path.basename(relative[-1]), f.read())


def obj_mesh(path):
    points, faces = [], []
    for line in open(path):
        fields = line.split()
        if fields and fields[0] == "v":
            points.append(tuple(float(x) for x in fields[1:4]))
        elif fields and fields[0] == "f":
            faces.append([int(x.split("/")[0]) - 1 for x in fields[1:]])
    return points, faces


def meshes(out):
    for name in ("cube.obj", "eight_genus2.obj", "sheet.obj"):
        copy(out, "Mesh", "Meshes", name)
    # A quad with texture and normal indices, negative indices and other records.
    write(out, "Mesh", "records.obj", "# records\no quad\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvn 0 0 1\n"
          "usemtl a\ns off\nf 1/1/1 2/1/1 3/1/1\nf -4//1 -2//1 -1//1\n")
    points, faces = obj_mesh(os.path.join(DATA, "Meshes", "torus.obj"))
    text = "OFF\n%d %d 0\n" % (len(points), len(faces))
    text += "".join("%g %g %g\n" % p for p in points)
    text += "".join("%d %s\n" % (len(f), " ".join(map(str, f))) for f in faces)
    write(out, "Mesh", "torus.off", text)
    points, faces = obj_mesh(os.path.join(DATA, "Meshes", "cube.obj"))
    header = ("ply\nformat {}\ncomment seed\nelement vertex %d\nproperty float x\nproperty float y\n"
              "property float z\nelement face %d\nproperty list uchar int vertex_indices\nend_header\n"
              % (len(points), len(faces)))
    ascii_body = "".join("%g %g %g\n" % p for p in points)
    ascii_body += "".join("%d %s\n" % (len(f), " ".join(map(str, f))) for f in faces)
    write(out, "Mesh", "cube_ascii.ply", header.format("ascii 1.0") + ascii_body)
    for order, name in (("<", "binary_little_endian"), (">", "binary_big_endian")):
        body = b"".join(struct.pack(order + "3f", *p) for p in points)
        body += b"".join(struct.pack(order + "B%di" % len(f), len(f), *f) for f in faces)
        write(out, "Mesh", "cube_%s.ply" % name, header.format(name + " 1.0").encode() + body)


def point_clouds(out):
    lines = open(os.path.join(DATA, "PointClouds", "torus.xyz")).read().splitlines()
    write(out, "PointCloud", "torus.xyz", "\n".join(lines[:60]) + "\n")
    write(out, "PointCloud", "points.csv", "x,y,z\n1.5,2,3\n-4,5e-1,6\n7;8;9\n0,0,1\n")
    write(out, "PointCloud", "ascii.vtp",
          '<?xml version="1.0"?>\n<VTKFile type="PolyData" version="0.1" byte_order="LittleEndian">\n'
          '<PolyData><Piece NumberOfPoints="4" NumberOfVerts="0" NumberOfLines="0" NumberOfStrips="0" '
          'NumberOfPolys="0"><Points><DataArray type="Float32" NumberOfComponents="3" format="ascii">\n'
          '0 0 0 1 0 0 0 1 0 0 0 1\n</DataArray></Points></Piece></PolyData></VTKFile>\n')
    raw = struct.pack("<12f", 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1)
    write(out, "PointCloud", "appended.vtp",
          b'<?xml version="1.0"?>\n<VTKFile type="PolyData" version="0.1" byte_order="LittleEndian" '
          b'header_type="UInt32">\n<PolyData><Piece NumberOfPoints="4" NumberOfVerts="0" NumberOfLines="0" '
          b'NumberOfStrips="0" NumberOfPolys="0"><Points><DataArray type="Float32" NumberOfComponents="3" '
          b'format="appended" offset="0"/></Points></Piece></PolyData>\n<AppendedData encoding="raw">\n_'
          + struct.pack("<I", len(raw)) + raw + b"\n</AppendedData>\n</VTKFile>\n")


def landmarks(out):
    copy(out, "Landmarks", "Landmarks", "caudate_left.mrk.json")
    write(out, "Landmarks", "points.fcsv",
          "# Markups fiducial file version = 4.11\n# CoordinateSystem = LPS\n"
          "# columns = id,x,y,z,ow,ox,oy,oz,vis,sel,lock,label,desc,associatedNodeID\n"
          "vtkMRMLMarkupsFiducialNode_0,-10.5,12.25,8,0,0,0,1,1,1,0,F-1,,\n"
          "vtkMRMLMarkupsFiducialNode_1,-11,13,8,0,0,0,1,1,1,0,F-2,a note,\n")
    write(out, "Landmarks", "points.csv", "label,x,y,z\np1,1,2,3\n\"p,2\",4.5,-5,6e0\n")


def springs_lattices_scripts(out):
    copy(out, "SpringFile", "Deform", "sheet_hat.springs")
    copy(out, "SpringFile", "Deform", "torus_pull.springs")
    write(out, "SpringFile", "separators.springs", "1,2,3\n4;5;6;7\n8\t9\t10 # comment\n")
    for name in ("cube3.lattice", "cube_holes.lattice"):
        copy(out, "Lattice", "Solids", name)
    copy(out, "SculptScript", "Solids", "arm.sculpt")
    write(out, "SculptScript", "actions.sculpt",
          "stiffness 4\nfix face 2\nunfix all\npull 1 2 3\nrelease\nrun 10\nextrude 5\ndelete 3\nplasticity\n")


def nifti(voxels, size, datatype=16, bitpix=32):
    """A NIfTI-1 single file (.nii) of float32 (or int16) voxels."""
    header = bytearray(348)
    struct.pack_into("<i", header, 0, 348)
    struct.pack_into("<8h", header, 40, 3, size[0], size[1], size[2], 1, 1, 1, 1)
    struct.pack_into("<hh", header, 70, datatype, bitpix)
    struct.pack_into("<8f", header, 76, 1, 1.0, 1.5, 2.0, 1, 1, 1, 1)
    struct.pack_into("<f", header, 108, 352.0)          # vox_offset
    struct.pack_into("<f", header, 112, 1.0)            # scl_slope
    struct.pack_into("<B", header, 123, 10)             # xyzt_units: mm, s
    struct.pack_into("<hh", header, 252, 1, 1)          # qform_code, sform_code
    struct.pack_into("<6f", header, 256, 0, 0, 0, -2.0, 3.0, 4.0)  # quaternion b c d, offsets
    struct.pack_into("<4f", header, 280, 1, 0, 0, -2.0)  # srow_x
    struct.pack_into("<4f", header, 296, 0, 1.5, 0, 3.0)
    struct.pack_into("<4f", header, 312, 0, 0, 2.0, 4.0)
    header[344:348] = b"n+1\0"
    fmt = "<%d%s" % (len(voxels), "f" if datatype == 16 else "h")
    return bytes(header) + b"\0\0\0\0" + struct.pack(fmt, *voxels)


def images(out, dicom):
    size = (4, 3, 3)
    ramp = [float(i % 7) * 10 for i in range(36)]
    write(out, "Nifti", "float.nii", nifti(ramp, size))
    write(out, "Nifti", "int16.nii", nifti([int(v) for v in ramp], size, datatype=4, bitpix=16))
    write(out, "Nifti", "float.nii.gz", gzip.compress(nifti(ramp, size), mtime=0))
    write(out, "Gzip", "float.nii.gz", gzip.compress(nifti(ramp, size), mtime=0))
    write(out, "Gzip", "text.gz", gzip.compress(b"not an image\n" * 20, mtime=0))
    data = struct.pack("<36f", *ramp)
    head = ("ObjectType = Image\nNDims = 3\nBinaryData = True\nBinaryDataByteOrderMSB = False\n"
            "TransformMatrix = 1 0 0 0 1 0 0 0 1\nOffset = -2 3 4\nElementSpacing = 1 1.5 2\n"
            "DimSize = 4 3 3\nElementType = MET_FLOAT\n")
    write(out, "MetaImage", "raw.mha", (head + "ElementDataFile = LOCAL\n").encode() + data)
    packed = zlib.compress(data)
    write(out, "MetaImage", "compressed.mha",
          (head + "CompressedData = True\nCompressedDataSize = %d\nElementDataFile = LOCAL\n" % len(packed)).encode()
          + packed)
    if dicom:
        with tempfile.TemporaryDirectory() as work:
            subprocess.run([sys.executable, os.path.join(ROOT, "Tools", "dicom_phantom.py"), work],
                           check=True, stdout=subprocess.DEVNULL)
            shutil.copy(os.path.join(work, "series", "slice_000.dcm"), os.path.join(out, "DicomWalk", "slice.dcm"))


def main():
    out = sys.argv[1] if len(sys.argv) > 1 else os.path.join(HERE, "Corpus")
    os.makedirs(os.path.join(out, "DicomWalk"), exist_ok=True)
    meshes(out)
    point_clouds(out)
    landmarks(out)
    springs_lattices_scripts(out)
    images(out, dicom=shutil.which("dump2dcm") is not None)


if __name__ == "__main__":
    main()
