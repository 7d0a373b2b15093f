#!/usr/bin/env python3
"""Writes a point cloud as a real scanner might have taken it: every point
moved by Gaussian noise, and outliers scattered uniformly in the cloud's
bounding box, seeded so that a run can be repeated.
  Tools/corrupt_cloud.py INPUT OUTPUT.xyz [--noise P] [--outliers Q] [--seed S]
INPUT: .xyz/.txt (x y z per line, '#' comments) or .off (its vertices).
--noise P     standard deviation of each coordinate's noise, in percent of the
              bounding box's diagonal (default 0.3)
--outliers Q  outliers added, in percent of the number of points (default 3)
The outliers follow the moved points in OUTPUT, so that its first lines are
the input's points in order."""
import argparse
import math
import random
import sys


def read_points(path):
    with open(path) as f:
        lines = [line.split("#")[0].split() for line in f]
    lines = [fields for fields in lines if fields]
    if path.lower().endswith(".off"):
        header = lines[0]
        counts = header[1:] if header[0].upper() == "OFF" and len(header) > 1 else lines[1]
        first = 1 if len(header) > 1 else 2
        vertices = int(counts[0])
        rows = lines[first:first + vertices]
    else:
        rows = lines
    points = []
    for number, fields in enumerate(rows, 1):
        try:
            points.append(tuple(float(v) for v in fields[:3]))
        except ValueError:
            sys.exit("%s: point %d is not three numbers: %s" % (path, number, " ".join(fields)))
        if len(fields) < 3:
            sys.exit("%s: point %d has fewer than three coordinates" % (path, number))
    if not points:
        sys.exit("%s: no points" % path)
    return points


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("input")
    parser.add_argument("output")
    parser.add_argument("--noise", type=float, default=0.3)
    parser.add_argument("--outliers", type=float, default=3.0)
    parser.add_argument("--seed", type=int, default=1)
    args = parser.parse_args()
    if not (args.noise >= 0 and args.outliers >= 0):
        sys.exit("--noise and --outliers must be >= 0 percent")
    points = read_points(args.input)
    low = [min(p[a] for p in points) for a in range(3)]
    high = [max(p[a] for p in points) for a in range(3)]
    diagonal = math.sqrt(sum((h - l) ** 2 for l, h in zip(low, high)))
    sigma = args.noise / 100.0 * diagonal
    rng = random.Random(args.seed)
    moved = [tuple(c + rng.gauss(0.0, sigma) for c in p) for p in points]
    count = int(round(args.outliers / 100.0 * len(points)))
    outliers = [tuple(rng.uniform(l, h) for l, h in zip(low, high)) for _ in range(count)]
    with open(args.output, "w") as f:
        f.write("# %s: %d points with %.3g %% noise (sigma %.4g mm per coordinate), then %d outliers; "
                "Tools/corrupt_cloud.py --seed %d\n" % (args.input, len(points), args.noise, sigma, count, args.seed))
        for p in moved + outliers:
            f.write("%.7g %.7g %.7g\n" % p)


if __name__ == "__main__":
    main()
