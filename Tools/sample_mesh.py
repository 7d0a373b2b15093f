#!/usr/bin/env python3
"""Writes points spread at random over an OFF mesh's faces (uniform by area,
seeded), as a scanner's cloud of that surface: its holes, openings and gaps
stay where the mesh has them, and the points are no mesh's vertices.
  Tools/sample_mesh.py INPUT.off OUTPUT.xyz [--points N] [--seed S]
--points N  the number of points (default: twice the vertices', within
            2,000-20,000)
Polygons are cut into fans of triangles; per-vertex colours (COFF) are
ignored."""
import argparse
import bisect
import math
import random


def read_off(path):
    with open(path) as f:
        rows = [line.split("#")[0].split() for line in f]
    rows = [r for r in rows if r]
    header = rows[0]
    start = 1 if header[0].upper().endswith("OFF") else 0
    if len(header) > 1 and start == 1:  # "OFF nv nf ne" on one line
        rows[0] = header[1:]
        start = 0
    nv, nf = int(rows[start][0]), int(rows[start][1])
    vertices = [tuple(float(x) for x in r[:3]) for r in rows[start + 1:start + 1 + nv]]
    triangles = []
    for r in rows[start + 1 + nv:start + 1 + nv + nf]:
        k = int(r[0])
        ids = [int(x) for x in r[1:1 + k]]
        triangles += [(ids[0], ids[j], ids[j + 1]) for j in range(1, k - 1)]
    return vertices, triangles


def area(a, b, c):
    u = [b[i] - a[i] for i in range(3)]
    v = [c[i] - a[i] for i in range(3)]
    n = (u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0])
    return 0.5 * math.sqrt(sum(x * x for x in n))


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("input")
    parser.add_argument("output")
    parser.add_argument("--points", type=int)
    parser.add_argument("--seed", type=int, default=1)
    args = parser.parse_args()
    vertices, triangles = read_off(args.input)
    count = args.points or min(max(2 * len(vertices), 2000), 20000)
    cumulative, total = [], 0.0
    for t in triangles:
        total += area(*(vertices[i] for i in t))
        cumulative.append(total)
    if total <= 0.0:
        raise SystemExit(f"{args.input}: the faces have no area")
    rng = random.Random(args.seed)
    with open(args.output, "w") as out:
        for _ in range(count):
            t = min(bisect.bisect(cumulative, rng.random() * total), len(triangles) - 1)  # rounding
            a, b, c = (vertices[i] for i in triangles[t])
            u, v = rng.random(), rng.random()
            if u + v > 1.0:
                u, v = 1.0 - u, 1.0 - v
            out.write(" ".join("%.7g" % (a[i] + u * (b[i] - a[i]) + v * (c[i] - a[i])) for i in range(3)) + "\n")


if __name__ == "__main__":
    main()
