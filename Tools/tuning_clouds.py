#!/usr/bin/env python3
"""Writes the synthetic point clouds the fitting choices are tuned on, seeded,
so that the CGAL scans stay a test set (Documentation/Performance.md):
  sphere.xyz     2000 points on a sphere of radius 50 mm
  ellipsoid.xyz  3000 points on an ellipsoid of semi-axes 60, 40, 20 mm
  peanut.xyz     two spheres of radius 30 mm, centres 40 mm apart, each
                 without the part inside the other, 0.2 mm Gaussian noise
  ellipsoid_dense.xyz, peanut_dense.xyz
                 the same shapes with 30000 points each, as dense as a scan
The bundled Data/PointClouds/torus.xyz (with --init torus) completes the set.
Usage: Tools/tuning_clouds.py OUTPUT_DIRECTORY"""
import math
import os
import random
import sys


def on_sphere(rng):
    while True:
        x, y, z = (rng.gauss(0.0, 1.0) for _ in range(3))
        n = math.sqrt(x * x + y * y + z * z)
        if n > 1e-9:
            return x / n, y / n, z / n


def write(path, comment, points):
    with open(path, "w") as f:
        f.write("# " + comment + "\n")
        for p in points:
            f.write("%.4f %.4f %.4f\n" % p)


def ellipsoid_points(rng, count):
    return [tuple(a * c for a, c in zip((60.0, 40.0, 20.0), on_sphere(rng))) for _ in range(count)]


def peanut_points(rng, count):
    peanut = []
    while len(peanut) < count:
        side = rng.choice((-20.0, 20.0))
        d = on_sphere(rng)
        p = (side + 30.0 * d[0], 30.0 * d[1], 30.0 * d[2])
        other = (p[0] + side, p[1], p[2])  # p relative to the other centre, -side
        if math.sqrt(sum(c * c for c in other)) < 30.0:
            continue
        peanut.append(tuple(c + rng.gauss(0.0, 0.2) for c in p))
    return peanut


def main():
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    out = sys.argv[1]
    os.makedirs(out, exist_ok=True)
    rng = random.Random(20261128)
    write(os.path.join(out, "sphere.xyz"), "2000 points on a sphere, radius 50 mm; Tools/tuning_clouds.py",
          [tuple(50.0 * c for c in on_sphere(rng)) for _ in range(2000)])
    write(os.path.join(out, "ellipsoid.xyz"), "3000 points on an ellipsoid 60:40:20 mm; Tools/tuning_clouds.py",
          ellipsoid_points(rng, 3000))
    write(os.path.join(out, "peanut.xyz"), "2725 points on two overlapping spheres, 0.2 mm noise; Tools/tuning_clouds.py",
          peanut_points(rng, 2725))
    write(os.path.join(out, "ellipsoid_dense.xyz"),
          "30000 points on an ellipsoid 60:40:20 mm; Tools/tuning_clouds.py",
          ellipsoid_points(rng, 30000))
    write(os.path.join(out, "peanut_dense.xyz"),
          "30000 points on two overlapping spheres, 0.2 mm noise; Tools/tuning_clouds.py",
          peanut_points(rng, 30000))


if __name__ == "__main__":
    main()
