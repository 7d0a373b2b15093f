#!/usr/bin/env python3
"""How well a segmentation that follows the image's grey matter can score
against an atlas label: the Dice, against the label, of exactly the label's
voxels whose intensity is nearer the grey-matter mode than the CSF and
white-matter modes (the halfway points between the modes). Such a mask has no
leak and misses only the voxels the atlas labels but the image shows as CSF
or white matter; an image-driven segmentation that stops at the tissue's
edges cannot score higher except by reproducing those voxels.

    Tools/tissue_ceiling.py [IMAGE LABELS BRAIN_MASK] [--label NAME=N ...]

Defaults: Colin27 (ch2.nii.gz), AAL (aal.nii.gz) and the brain-extracted
ch2bet.nii.gz from Debian's mricron-data, and AAL's caudates (71, 72). The
modes are the histogram peaks of the brain's voxels below 45 (CSF), 45-100
(grey matter) and above 100 (white matter), ranges that hold for this T1
image's intensities (0-133 in the brain). Needs nibabel and numpy (python3-nibabel).
"""
import argparse

import nibabel
import numpy

TEMPLATES = "/usr/share/mricron/templates/"


def mode(values, low, high):
    """The most frequent intensity in [low, high), to whole units."""
    units, counts = numpy.unique(numpy.round(values[(values >= low) & (values < high)]), return_counts=True)
    return units[counts.argmax()]


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("image", nargs="?", default=TEMPLATES + "ch2.nii.gz")
    parser.add_argument("labels", nargs="?", default=TEMPLATES + "aal.nii.gz")
    parser.add_argument("brain", nargs="?", default=TEMPLATES + "ch2bet.nii.gz")
    parser.add_argument("--label", action="append", default=[], help="NAME=N, repeatable")
    args = parser.parse_args()
    labels = [(n.split("=")[0], int(n.split("=")[1])) for n in args.label] or [("caudate_left", 71),
                                                                                  ("caudate_right", 72)]
    image = numpy.asanyarray(nibabel.load(args.image).dataobj, dtype=numpy.float64)
    atlas = numpy.asanyarray(nibabel.load(args.labels).dataobj)
    brain = numpy.asanyarray(nibabel.load(args.brain).dataobj) > 0
    if image.shape != atlas.shape or image.shape != brain.shape:
        raise SystemExit(f"{args.image}, {args.labels} and {args.brain} are not on one grid")
    values = image[brain]
    csf, grey, white = mode(values, 0, 45), mode(values, 45, 100), mode(values, 100, 140)
    low, high = 0.5 * (csf + grey), 0.5 * (grey + white)
    print(f"modes: CSF {csf:.1f}, grey {grey:.1f}, white {white:.1f}; grey window {low:.2f}..{high:.2f}")
    for name, label in labels:
        reference = atlas == label
        if not reference.any():
            raise SystemExit(f"{args.labels}: no voxel has label {label}")
        grey_only = reference & (image >= low) & (image <= high)
        dice = 2.0 * grey_only.sum() / (grey_only.sum() + reference.sum())
        print(f"{name} (label {label}): {reference.sum()} voxels, {(reference & (image < low)).sum()} CSF-dark, "
              f"{(reference & (image > high)).sum()} white-bright; the grey ones alone score Dice {dice:.3f}")


if __name__ == "__main__":
    main()
