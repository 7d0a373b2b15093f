#!/usr/bin/env python3
"""Where an edge detector finds a labelled structure's boundary, against
where the label puts it: along the boundary's normals, the offset (mm,
positive outward) of the peak of the Gaussian-smoothed gradient magnitude
from the label's boundary and, given a segmentation's surface.vtp, its
vertices' signed distances to that boundary. On a synthesized subject
(`dynsub subject --set mode=synthesized`) a structure's intensity changes at
its label's boundary, yet the gradient's peak lies beyond it where the
tissues around it have edges of their own within the filter's reach.

    Tools/edge_offset.py IMAGE LABELS --label N[,M...] [--sigma MM] [--surface surface.vtp]

The image and the labels must share a grid. The boundary is the labelled
voxels' faces: each voxel's signed distance is its centre's distance to the
nearest voxel of the other side, less half a voxel (negative inside), and
the normals are the gradient of that distance smoothed by 1 voxel. Prints
medians and means over the boundary voxels (and the surface's vertices).
Needs nibabel, numpy, scipy and VTK's Python bindings (python3-vtk9).
"""
import argparse

import nibabel
import numpy
from scipy import ndimage


def signed_distance(mask, spacing):
    """Voxel centres' distance (mm) to the mask's faces, negative inside."""
    half = 0.5 * min(spacing)
    inside = ndimage.distance_transform_edt(mask, sampling=spacing) - half
    outside = ndimage.distance_transform_edt(~mask, sampling=spacing) - half
    return numpy.where(mask, -inside, outside)


def load(path):
    """A NIfTI image, or an error naming the file."""
    try:
        return nibabel.load(path)
    except (OSError, nibabel.filebasedimages.ImageFileError) as error:
        raise SystemExit(f"{path}: cannot read it as an image ({error})")


def surface_points_in_voxels(path, affine):
    """surface.vtp's points (LPS mm) as continuous voxel indices of the NIfTI grid (RAS)."""
    from vtkmodules.util.numpy_support import vtk_to_numpy
    from vtkmodules.vtkIOXML import vtkXMLPolyDataReader
    reader = vtkXMLPolyDataReader()
    reader.SetFileName(path)
    reader.Update()
    if reader.GetOutput().GetNumberOfPoints() == 0:
        raise SystemExit(f"{path}: no points (not a surface.vtp?)")
    lps = vtk_to_numpy(reader.GetOutput().GetPoints().GetData()).astype(float)
    ras = lps * numpy.array([-1.0, -1.0, 1.0])
    return (numpy.linalg.inv(affine) @ numpy.c_[ras, numpy.ones(len(ras))].T)[:3]


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("image")
    parser.add_argument("labels")
    parser.add_argument("--label", required=True, help="the structure's label value(s), N[,M...]")
    parser.add_argument("--sigma", type=float, default=1.0, help="the derivative's smoothing, mm (segment's default)")
    parser.add_argument("--surface", help="a segmentation's surface.vtp (LPS mm)")
    args = parser.parse_args()

    labels_file = load(args.labels)
    image_file = load(args.image)
    if labels_file.shape[:3] != image_file.shape[:3] or not numpy.allclose(labels_file.affine, image_file.affine):
        raise SystemExit(f"{args.image} and {args.labels} are not on one grid")
    spacing = tuple(float(s) for s in labels_file.header.get_zooms()[:3])
    mask = numpy.isin(numpy.asarray(labels_file.dataobj), [int(v) for v in args.label.split(",")])
    if not mask.any():
        raise SystemExit(f"{args.labels}: no voxel has label {args.label}")
    distance = signed_distance(mask, spacing)

    # Boundary voxels (labelled, with an unlabelled 6-neighbour), their outward
    # normals in voxel units, and the boundary half a voxel out along them.
    normals = numpy.stack(numpy.gradient(ndimage.gaussian_filter(distance, 1.0), *spacing))
    normals = normals / (numpy.linalg.norm(normals, axis=0) + 1e-12)
    voxels = numpy.argwhere(mask & ~ndimage.binary_erosion(mask))
    n = normals[:, voxels[:, 0], voxels[:, 1], voxels[:, 2]].T / numpy.array(spacing)  # index units per mm
    start = voxels + 0.5 * min(spacing) * n
    offsets = numpy.arange(-2.0, 2.0001, 0.05)  # mm along the normal
    magnitude = ndimage.gaussian_gradient_magnitude(
        numpy.asarray(image_file.dataobj, dtype=float), [args.sigma / s for s in spacing])
    # Cubic along the profile: linear interpolation peaks only at voxel centres.
    profile = numpy.stack([ndimage.map_coordinates(magnitude, (start + t * n).T, order=3) for t in offsets], axis=1)
    where_zero = numpy.stack([ndimage.map_coordinates(distance, (start + t * n).T, order=1) for t in offsets], axis=1)
    peak = offsets[profile.argmax(axis=1)] - offsets[numpy.abs(where_zero).argmin(axis=1)]
    print(f"gradient peak from the label's boundary (sigma {args.sigma} mm, {len(peak)} boundary voxels): "
          f"median {numpy.median(peak):+.3f} mm, mean {peak.mean():+.3f} mm")
    if args.surface:
        at = ndimage.map_coordinates(distance, surface_points_in_voxels(args.surface, labels_file.affine), order=1)
        print(f"surface from the label's boundary ({len(at)} vertices): median {numpy.median(at):+.3f} mm, "
              f"mean {at.mean():+.3f} mm, within 0.5 mm {100.0 * (numpy.abs(at) < 0.5).mean():.0f} %")


if __name__ == "__main__":
    main()
