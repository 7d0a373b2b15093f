#!/usr/bin/env python3
"""Checks of DynSubSegment as 3D Slicer and nipype see it.

    slicer_module_check.py descriptor MODULE
        The descriptor keeps the rules Slicer's module parser enforces, names
        the same flags as the program's --help, and nipype's Slicer interface
        generator (nipype.interfaces.slicer.generate_classes) builds a class
        from it that composes a command line.
    slicer_module_check.py nipype-run MODULE IMAGE LANDMARKS WORKDIR
        Runs the module through that generated nipype interface.
    slicer_module_check.py dice LABELMAP.nrrd LABEL REFERENCE.nii.gz REF_LABEL MINIMUM
        Reads the module's NRRD labelmap with a reader written here, checks
        that its grid is the reference's, and that the structure of value
        LABEL has Dice >= MINIMUM.
    slicer_module_check.py segmentation SEGMENTATION.seg.nrrd LABELMAP.nrrd NAME=LABEL...
        The 3D Slicer segmentation as Slicer reads it: teem (the NRRD
        format's own library, Debian's teem-apps) reads the file; its fields
        name each segment, in order, with its label value, one layer, a
        colour of its own and the whole grid as its extent; its voxels are
        the labelmap's.

Run with Debian's python3 (python3-nipype, python3-nibabel) and teem-apps.
"""
import gzip
import os
import re
import subprocess
import sys
import xml.etree.ElementTree as ElementTree

import numpy

# The parameter types of the Slicer Execution Model (ModuleDescriptionParser).
SCALARS = {"integer", "float", "double", "boolean", "string"}
TYPES = (SCALARS | {t + "-vector" for t in ("integer", "float", "double", "string")}
         | {t + "-enumeration" for t in ("integer", "float", "double", "string")}
         | {"file", "directory", "image", "geometry", "point", "pointfile", "region", "table", "transform",
            "measurement"})
NEEDS_CHANNEL = {"file", "directory", "image", "geometry", "transform", "table", "pointfile", "measurement"}
IMAGE_TYPES = {"scalar", "label", "tensor", "diffusion-weighted", "vector", "model", "any"}


def fail(message):
    sys.exit("FAIL: " + message)


def check_descriptor(module):
    run = subprocess.run([module, "--xml"], capture_output=True, text=True)
    if run.returncode != 0 or run.stderr:
        fail(f"--xml: exit {run.returncode}, stderr {run.stderr!r}")
    if not run.stdout.startswith("<?xml"):
        fail("--xml does not start with <?xml: " + run.stdout[:60])
    root = ElementTree.fromstring(run.stdout)
    if root.tag != "executable":
        fail("the root element is not <executable>")
    for tag in ("category", "title", "description", "version", "documentation-url", "license"):
        if not (root.findtext(tag) or "").strip():
            fail(f"<{tag}> is missing or empty")
    if not re.match(r"(https?|file)://", root.findtext("documentation-url")):
        fail(f"<documentation-url> {root.findtext('documentation-url')!r} is not a URL")
    names, flags, indices = set(), set(), []
    for group in root.findall("parameters"):
        if not (group.findtext("label") or "").strip():
            fail("a <parameters> group has no <label>")
        if group.get("advanced") not in (None, "true", "false"):
            fail("advanced must be true or false")
        for p in group:
            if p.tag in ("label", "description"):
                continue
            name = p.findtext("name")
            if p.tag not in TYPES:
                fail(f"{name}: unknown parameter type <{p.tag}>")
            if not name or not re.fullmatch(r"[A-Za-z_][A-Za-z0-9_]*", name) or name in names:
                fail(f"parameter name {name!r} is missing, not an identifier, or repeated")
            names.add(name)
            if not (p.findtext("label") and p.findtext("description")):
                fail(f"{name}: needs a <label> and a <description>")
            index, longflag, flag = p.findtext("index"), p.findtext("longflag"), p.findtext("flag")
            if index is not None:
                if longflag or flag:
                    fail(f"{name}: an indexed parameter has no flag")
                indices.append(int(index))
            else:
                # nipype names an input after its longflag, so it must be an identifier (Slicer's
                # own modules use camelCase flags).
                if not longflag or not re.fullmatch(r"--[a-z][A-Za-z0-9]*", longflag) or longflag in flags:
                    fail(f"{name}: longflag {longflag!r} is missing, malformed or repeated")
                flags.add(longflag)
            channel = p.findtext("channel")
            if p.tag in NEEDS_CHANNEL and channel not in ("input", "output"):
                fail(f"{name}: <{p.tag}> needs <channel> input or output")
            if p.tag not in NEEDS_CHANNEL and channel is not None:
                fail(f"{name}: a plain value has no channel")
            if p.tag in ("image", "geometry") and p.get("type") not in IMAGE_TYPES:
                fail(f"{name}: type {p.get('type')!r}")
            if p.tag == "geometry" and channel == "output" and ".vtk" not in (p.get("fileExtensions") or ".vtk"):
                # nipype names an output model by the first extension declared, .vtk without one.
                fail(f"{name}: an output model that declares extensions must accept .vtk")
            reference = p.get("reference")
            if reference is not None and reference not in names:
                fail(f"{name}: reference {reference!r} names no earlier parameter")
            system = p.get("coordinateSystem")
            if p.tag in ("point", "region", "pointfile") and system not in ("lps", "ras", "ijk"):
                fail(f"{name}: coordinateSystem {system!r} (Slicer accepts lowercase lps, ras or ijk)")
            if p.get("multiple") not in (None, "true", "false"):
                fail(f"{name}: multiple must be true or false")
            default = p.findtext("default")
            if p.tag.endswith("-enumeration"):
                elements = [e.text for e in p.findall("element")]
                if not elements or default not in elements:
                    fail(f"{name}: default {default!r} is not one of {elements}")
            if p.tag == "boolean" and default != "false":
                # Slicer passes a boolean's flag only when it is checked: a true default could not be unset.
                fail(f"{name}: a boolean's default must be false, got {default!r}")
            if p.tag in ("integer", "double", "float"):
                value = float(default)
                if p.tag == "integer" and not re.fullmatch(r"-?[0-9]+", default):
                    fail(f"{name}: integer default {default!r}")
                c = p.find("constraints")
                if c is not None:
                    low, high = float(c.findtext("minimum")), float(c.findtext("maximum"))
                    if not low <= value <= high or not float(c.findtext("step")) > 0:
                        fail(f"{name}: default {value} outside [{low}, {high}] or a bad step")
    if sorted(indices) != list(range(len(indices))):
        fail(f"indices {sorted(indices)} are not 0..n-1")
    # The program accepts exactly the flags the descriptor declares (and --xml, --help).
    helptext = subprocess.run([module, "--help"], capture_output=True, text=True).stdout
    accepted = set(re.findall(r"^\s+(?:-h,)?(--[a-z][A-Za-z0-9]*)", helptext, re.M)) - {"--help", "--xml"}
    if accepted != flags:
        fail(f"flags of --help {sorted(accepted)} differ from the descriptor's {sorted(flags)}")

    interface = generated_interface(module)
    node = interface()
    node.inputs.inputVolume = __file__  # any existing file: only the command line is composed here
    node.inputs.labelmap = "out.nrrd"
    node.inputs.sigma = 1.5
    node.inputs.potential = "gradient"
    node.inputs.pointsReachEnds = True
    line = node.cmdline
    for expected in ("DynSubSegment ", "--labelmap out.nrrd", "--sigma 1.500000", "--potential gradient",
                     "--pointsReachEnds ", os.path.basename(__file__)):
        if expected not in line:
            fail(f"nipype's command line {line!r} lacks {expected!r}")
    print(f"descriptor: {len(names)} parameters, {len(flags)} flags, Slicer's rules kept; nipype built "
          f"{interface.__name__} and composed: {line}")


def generated_interface(module):
    from nipype.interfaces.slicer.generate_classes import generate_class
    # Slicer finds modules by directory; nipype runs them by name from PATH.
    os.environ["PATH"] = os.path.dirname(module) + os.pathsep + os.environ["PATH"]
    _, code, class_name = generate_class(os.path.basename(module), [])
    namespace = {}
    exec("from nipype.interfaces.base import CommandLine, CommandLineInputSpec, SEMLikeCommandLine, "
         "TraitedSpec, File, Directory, traits, isdefined, InputMultiPath, OutputMultiPath\n" + code, namespace)
    return namespace[class_name]


def nipype_run(module, image, landmarks, workdir):
    """Runs the module twice through nipype's generated class, as a nipype user would: the boundary
    points as a list of [x, y, z] (nipype writes each as "--seed [x, y, z]"), then one point inside
    (written "--inside x y z"). nipype names the outputs it is asked for (True) itself."""
    import json
    from nipype import logging
    logging.getLogger("nipype.interface").setLevel("WARNING")  # not every <filter-progress> line
    interface = generated_interface(module)
    markups = json.load(open(landmarks))["markups"][0]
    if markups.get("coordinateSystem", "LPS") != "LPS":
        fail(f"{landmarks}: expected LPS points")
    points = [[float(v) for v in p["position"]] for p in markups["controlPoints"]]
    for name, inputs, expected in (
            ("boundary points", {"seed": points}, "--seed [%s, %s, %s]" % tuple(points[0])),
            ("a point inside", {"inside": numpy.mean(points, axis=0).tolist()}, "--inside ")):
        run_dir = os.path.join(workdir, name.replace(" ", "_"))
        os.makedirs(run_dir)
        os.chdir(run_dir)
        node = interface()
        node.inputs.inputVolume = image
        for key, value in inputs.items():
            setattr(node.inputs, key, value)
        node.inputs.labelmap = True
        node.inputs.model = True
        node.inputs.segmentation = True
        node.inputs.report = "report.json"
        if expected not in node.cmdline:
            fail(f"nipype's command line {node.cmdline!r} lacks {expected!r}")
        outputs = node.run().outputs
        for path in (outputs.labelmap, outputs.model, outputs.segmentation, outputs.report):
            if not os.path.getsize(path) > 0:
                fail(f"nipype run with {name}: {path} is missing or empty")
        report = json.load(open(outputs.report))
        if name == "boundary points" and report["landmark_count"] != len(points):
            fail(f"nipype run with {name}: {report['landmark_count']} points reached the module, not {len(points)}")
        if not outputs.segmentation.endswith(".seg.nrrd"):
            fail(f"nipype named the segmentation {outputs.segmentation}, not .seg.nrrd")
        if name == "a point inside" and not report["init"].startswith("inside:"):
            fail(f"nipype run with {name}: the module started from {report['init']!r}")
        print(f"nipype ran with {name}: {node.cmdline[:160]}...\n  -> {outputs.labelmap}, {outputs.model}")


NRRD_TYPES = {"unsigned char": numpy.uint8, "uchar": numpy.uint8, "uint8": numpy.uint8,
              "uint8_t": numpy.uint8, "short": numpy.int16, "int16": numpy.int16,
              "unsigned short": numpy.uint16, "uint16": numpy.uint16, "float": numpy.float32}


def read_nrrd(path):
    """A minimal reader for single-file NRRD: returns (array in index order, 4x4 LPS affine)."""
    data = open(path, "rb").read()
    head, _, body = data.partition(b"\n\n")
    fields = {}
    lines = head.decode("ascii").splitlines()
    if not lines[0].startswith("NRRD000"):
        fail(f"{path}: not NRRD")
    for line in lines[1:]:
        if line.startswith("#"):
            continue
        key, _, value = line.partition(":")
        fields[key.strip()] = value.strip().lstrip("=")
    if fields.get("space") != "left-posterior-superior":
        fail(f"{path}: space {fields.get('space')!r}, expected left-posterior-superior")
    sizes = [int(n) for n in fields["sizes"].split()]
    dtype = numpy.dtype(NRRD_TYPES[fields["type"]]).newbyteorder("<" if fields.get("endian", "little") == "little"
                                                                  else ">")
    raw = gzip.decompress(body) if fields["encoding"] == "gzip" else body
    array = numpy.frombuffer(raw, dtype=dtype).reshape(sizes, order="F")
    vectors = re.findall(r"\(([^)]*)\)", fields["space directions"])
    affine = numpy.eye(4)
    for axis, vector in enumerate(vectors):
        affine[:3, axis] = [float(v) for v in vector.split(",")]
    affine[:3, 3] = [float(v) for v in re.findall(r"\(([^)]*)\)", fields["space origin"])[0].split(",")]
    return array, affine


def dice(labelmap, label, reference, reference_label, minimum):
    import nibabel
    ours, affine = read_nrrd(labelmap)
    ref = nibabel.load(reference)
    ref_lps = numpy.diag([-1.0, -1.0, 1.0, 1.0]) @ ref.affine
    if ours.shape != ref.shape or not numpy.allclose(affine, ref_lps, atol=1e-4):
        fail(f"{labelmap}: grid {ours.shape} {affine.tolist()} is not the reference's {ref.shape} {ref_lps.tolist()}")
    values = set(numpy.unique(ours).tolist())
    if 0 not in values or label not in values:
        fail(f"{labelmap}: values {values}, expected 0 and {label} among them")
    a = ours == label
    b = numpy.asanyarray(ref.dataobj) == reference_label
    score = 2.0 * numpy.count_nonzero(a & b) / (numpy.count_nonzero(a) + numpy.count_nonzero(b))
    print(f"Dice {score:.4f} against {reference} label {reference_label} (minimum {minimum})")
    if not score >= minimum:
        fail(f"Dice {score:.4f} < {minimum}")


def segmentation(path, labelmap, segments):
    import tempfile
    head = subprocess.run(["teem-unu", "head", path], capture_output=True, text=True)
    if head.returncode != 0:
        fail(f"teem cannot read {path}: {head.stderr.strip()}")
    fields = dict(line.split(":=", 1) for line in head.stdout.splitlines() if ":=" in line)
    if fields.get("Segmentation_SourceRepresentation") != "Binary labelmap":
        fail(f"{path}: Segmentation_SourceRepresentation is {fields.get('Segmentation_SourceRepresentation')!r}")
    with tempfile.TemporaryDirectory() as work:
        raw = os.path.join(work, "raw.nrrd")
        subprocess.run(["teem-unu", "save", "-i", path, "-f", "nrrd", "-e", "raw", "-o", raw], check=True)
        voxels, affine = read_nrrd(raw)
    expected, expected_affine = read_nrrd(labelmap)
    if voxels.shape != expected.shape or not numpy.allclose(affine, expected_affine, atol=1e-6):
        fail(f"{path}: its grid is not the labelmap's")
    if not numpy.array_equal(voxels.astype(numpy.int32), expected.astype(numpy.int32)):
        fail(f"{path}: its voxels differ from {labelmap}'s in {numpy.count_nonzero(voxels != expected)} places")
    colors = set()
    for index, segment in enumerate(segments):
        name, label = segment.rsplit("=", 1)
        key = f"Segment{index}_"
        if fields.get(key + "Name") != name or fields.get(key + "LabelValue") != label:
            fail(f"{path}: segment {index} is {fields.get(key + 'Name')!r} = {fields.get(key + 'LabelValue')!r}, "
                 f"expected {name!r} = {label}")
        if fields.get(key + "Layer") != "0" or not fields.get(key + "ID"):
            fail(f"{path}: segment {index} has no ID or is not in layer 0")
        color = tuple(float(c) for c in fields[key + "Color"].split())
        if len(color) != 3 or not all(0 <= c <= 1 for c in color) or color in colors:
            fail(f"{path}: segment {index}'s colour {color} is not three values in 0-1 of its own")
        colors.add(color)
        # Slicer crops a layer to its first segment's extent, so each gives the whole grid.
        grid = [int(v) for n in voxels.shape for v in (0, n - 1)]
        if [int(v) for v in fields[key + "Extent"].split()] != grid:
            fail(f"{path}: segment {index}'s extent {fields[key + 'Extent']} is not the grid {grid}")
        print(f"segment {index}: {name} = {label}, colour {color}, {numpy.count_nonzero(voxels == int(label))} voxels")
    if f"Segment{len(segments)}_ID" in fields:
        fail(f"{path}: more than the {len(segments)} segments expected")


if __name__ == "__main__":
    command = sys.argv[1] if len(sys.argv) > 1 else ""
    if command == "descriptor" and len(sys.argv) == 3:
        check_descriptor(os.path.abspath(sys.argv[2]))
    elif command == "nipype-run" and len(sys.argv) == 6:
        nipype_run(os.path.abspath(sys.argv[2]), *[os.path.abspath(a) for a in sys.argv[3:]])
    elif command == "segmentation" and len(sys.argv) >= 5:
        segmentation(sys.argv[2], sys.argv[3], sys.argv[4:])
    elif command == "dice" and len(sys.argv) == 7:
        dice(sys.argv[2], int(sys.argv[3]), sys.argv[4], int(sys.argv[5]), float(sys.argv[6]))
    else:
        sys.exit(__doc__)
