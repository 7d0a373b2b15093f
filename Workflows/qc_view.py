"""The data of one job's interactive view on the QC page (NiiVue): the T1w
cropped to the structures' neighbourhood, their labelmap on the same crop,
and the fitted surfaces as triangles (one mesh).

It is written as a small script (`window.dynsubViews[ID] = {...}`) rather
than as NIfTI and mesh files, because a page opened from disk (file://) may
load scripts but may not fetch files beside it. The page loads it only when
the view is opened, so a cohort's page stays light.

Sizes: the crop keeps MARGIN_MM around the surface and is stored as 8 bits
(a robust window of its own intensities, which is all a viewer needs), and
the surface is the limit surface sampled 2 x 2 per control face; a caudate
comes to about 200 kB.
"""
import base64
import gzip
import json
import os
import subprocess

import nibabel
import numpy as np

MARGIN_MM = 10.0
SAMPLES_PER_FACE = 2
WINDOW_PERCENTILES = (1.0, 99.5)


def _read_obj(path):
    """Vertices (N x 3) and triangles (M x 3, from 0) of a triangle OBJ."""
    points, triangles = [], []
    with open(path) as f:
        for line in f:
            fields = line.split()
            if not fields:
                continue
            if fields[0] == "v":
                points.append([float(x) for x in fields[1:4]])
            elif fields[0] == "f":
                triangles.append([int(x.split("/")[0]) - 1 for x in fields[1:4]])
    return np.array(points, dtype=np.float32), np.array(triangles, dtype=np.uint32)


def _nifti_base64(data, affine):
    image = nibabel.Nifti1Image(data, affine)
    image.header.set_xyzt_units("mm")
    return base64.b64encode(gzip.compress(image.to_bytes(), 6)).decode("ascii")


def _crop(image, ras):
    """The image's voxel box holding the points (RAS mm) and MARGIN_MM around them."""
    corners = np.array([[x, y, z] for x in (ras[:, 0].min() - MARGIN_MM, ras[:, 0].max() + MARGIN_MM)
                        for y in (ras[:, 1].min() - MARGIN_MM, ras[:, 1].max() + MARGIN_MM)
                        for z in (ras[:, 2].min() - MARGIN_MM, ras[:, 2].max() + MARGIN_MM)])
    voxels = nibabel.affines.apply_affine(np.linalg.inv(image.affine), corners)
    shape = np.array(image.shape[:3])
    low = np.clip(np.floor(voxels.min(axis=0)).astype(int), 0, shape - 1)
    high = np.clip(np.ceil(voxels.max(axis=0)).astype(int) + 1, low + 1, shape)
    return tuple(slice(a, b) for a, b in zip(low, high))


def view_script(key, t1w, labelmap, control_meshes, dynsub, work):
    """The view of one job, as the text of its .js file.

    key names it on the page; control_meshes are the structures'
    control_mesh.obj files (LPS mm), whose limit surfaces `dynsub limit`
    samples into work/."""
    all_points, all_triangles = [], []
    for n, control_mesh in enumerate(control_meshes):
        surface = os.path.join(work, f"view_surface_{n}.obj")
        subprocess.run([dynsub, "limit", control_mesh, "--samples-per-face", str(SAMPLES_PER_FACE), "--out", surface],
                       check=True, capture_output=True, text=True)
        points, triangles = _read_obj(surface)
        if len(points) == 0 or len(triangles) == 0:
            raise ValueError(f"{surface}: the limit surface has no triangles")
        all_triangles.append(triangles + sum(len(p) for p in all_points))
        all_points.append(points)
    points, triangles = np.concatenate(all_points), np.concatenate(all_triangles).astype(np.uint32)
    ras = points * np.array([-1, -1, 1], dtype=np.float32)  # NiiVue's world is the NIfTI's RAS
    image = nibabel.load(t1w)
    box = _crop(image, ras)
    cropped = image.slicer[box]
    intensities = np.asanyarray(cropped.dataobj, dtype=np.float32)
    if intensities.ndim > 3:
        intensities = intensities[..., 0]
    low, high = np.percentile(intensities, WINDOW_PERCENTILES)
    scaled = np.clip((intensities - low) / max(high - low, 1e-6) * 255.0, 0, 255).astype(np.uint8)
    labels = nibabel.load(labelmap).slicer[box]
    view = {
        "image": _nifti_base64(scaled, cropped.affine),
        "labels": _nifti_base64(np.asanyarray(labels.dataobj).astype(np.uint8), labels.affine),
        "points": base64.b64encode(ras.tobytes()).decode("ascii"),
        "triangles": base64.b64encode(triangles.tobytes()).decode("ascii"),
    }
    return (f"window.dynsubViews = window.dynsubViews || {{}};\n"
            f"window.dynsubViews[{json.dumps(key)}] = {json.dumps(view)};\n")
