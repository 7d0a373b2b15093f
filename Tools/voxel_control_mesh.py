#!/usr/bin/env python3
"""Build a coarse quad control mesh around a point cloud or a triangle mesh.

    voxel_control_mesh.py INPUT CELLS OUT.obj

The shape is covered by a grid of cubes, CELLS of them along its longest side.
Cubes that contain a data point form a shell; the solid is everything the
outside cannot reach without crossing the shell (a flood fill from a padded
corner), so a handle wider than about two cubes stays a handle. Where the cube
faces would meet non-manifoldly (two cubes sharing only an edge or a corner)
the cubes around that edge or corner are added. The boundary faces of the solid,
oriented outwards, are the control mesh; its genus is printed so that CELLS can
be chosen to match the genus of the shape.

INPUT is an .xyz file (x y z first on each line) or an .off mesh, whose faces
are sampled densely (20 points per triangle) so that sparse vertices do not
leave gaps in the shell. Only the Python standard library is used.

This is how Data/Meshes/kitten_genus1.obj was made (CELLS = 16, the coarsest
grid that keeps the kitten's tail handle open).
"""
import collections
import random
import sys

NEIGHBOURS = [(1, 0, 0), (-1, 0, 0), (0, 1, 0), (0, -1, 0), (0, 0, 1), (0, 0, -1)]


def read_points(path):
    if not path.endswith(".off"):
        points = []
        for line in open(path):
            fields = line.split()
            if len(fields) >= 3:
                points.append(tuple(float(f) for f in fields[:3]))
        return points
    tokens = open(path).read().split()
    if tokens[0] != "OFF":
        sys.exit(f"{path}: not an OFF file")
    vertex_count, face_count = int(tokens[1]), int(tokens[2])
    at = 4
    vertices = [tuple(float(t) for t in tokens[at + 3 * i:at + 3 * i + 3]) for i in range(vertex_count)]
    at += 3 * vertex_count
    points = list(vertices)
    rng = random.Random(1)
    for _ in range(face_count):
        n = int(tokens[at])
        face = [int(t) for t in tokens[at + 1:at + 1 + n]]
        at += 1 + n
        for t in range(1, n - 1):
            a, b, c = vertices[face[0]], vertices[face[t]], vertices[face[t + 1]]
            for _ in range(20):
                r, s = rng.random(), rng.random()
                if r + s > 1:
                    r, s = 1 - r, 1 - s
                points.append(tuple(a[j] + r * (b[j] - a[j]) + s * (c[j] - a[j]) for j in range(3)))
    return points


def boundary_quads(solid):
    """Faces between a solid cube and an empty one, counter-clockwise seen from outside."""
    quads = []
    for cube in solid:
        for axis in range(3):
            for side in (0, 1):
                neighbour = list(cube)
                neighbour[axis] += 1 if side else -1
                if tuple(neighbour) in solid:
                    continue
                corner = list(cube)
                corner[axis] += side
                a, b = [k for k in range(3) if k != axis]
                quad = []
                for du, dv in [(0, 0), (1, 0), (1, 1), (0, 1)]:
                    vertex = list(corner)
                    vertex[a] += du
                    vertex[b] += dv
                    quad.append(tuple(vertex))
                # (a, b) is a right-handed pair for axes x and z, left-handed for y.
                if (side == 1) != (axis != 1):
                    quad.reverse()
                quads.append(quad)
    return quads


def non_manifold(quads):
    """Edges not shared by exactly two quads, and vertices whose quads form more than one fan."""
    edge_use = collections.Counter()
    around = collections.defaultdict(list)
    for index, quad in enumerate(quads):
        for i in range(4):
            edge_use[frozenset((quad[i], quad[(i + 1) % 4]))] += 1
            around[quad[i]].append(index)
    bad_edges = [tuple(e) for e, count in edge_use.items() if count != 2]
    bad_vertices = []
    for vertex, faces in around.items():
        reached, stack = {faces[0]}, [faces[0]]
        while stack:
            f = stack.pop()
            for g in faces:
                if g not in reached and len(set(quads[f]) & set(quads[g])) == 2:
                    reached.add(g)
                    stack.append(g)
        if len(reached) != len(faces):
            bad_vertices.append(vertex)
    return bad_edges, bad_vertices


def main():
    if len(sys.argv) != 4:
        sys.exit(__doc__)
    points = read_points(sys.argv[1])
    cells = int(sys.argv[2])
    low = [min(p[k] for p in points) for k in range(3)]
    high = [max(p[k] for p in points) for k in range(3)]
    size = max(high[k] - low[k] for k in range(3)) / cells
    dims = [int((high[k] - low[k]) / size) + 3 for k in range(3)]  # one empty layer each side

    shell = {tuple(int((p[k] - low[k]) / size) + 1 for k in range(3)) for p in points}
    outside, queue = {(0, 0, 0)}, collections.deque([(0, 0, 0)])
    while queue:
        cube = queue.popleft()
        for d in NEIGHBOURS:
            n = (cube[0] + d[0], cube[1] + d[1], cube[2] + d[2])
            if all(0 <= n[k] < dims[k] for k in range(3)) and n not in outside and n not in shell:
                outside.add(n)
                queue.append(n)
    solid = {(i, j, k) for i in range(dims[0]) for j in range(dims[1]) for k in range(dims[2])} - outside

    while True:
        quads = boundary_quads(solid)
        bad_edges, bad_vertices = non_manifold(quads)
        if not bad_edges and not bad_vertices:
            break
        for a, b in bad_edges:
            axis = [k for k in range(3) if a[k] != b[k]][0]
            u, v = [k for k in range(3) if k != axis]
            for du in (-1, 0):
                for dv in (-1, 0):
                    cube = [0, 0, 0]
                    cube[axis] = min(a[axis], b[axis])
                    cube[u], cube[v] = a[u] + du, a[v] + dv
                    solid.add(tuple(cube))
        for vertex in bad_vertices:
            for d in [(x, y, z) for x in (-1, 0) for y in (-1, 0) for z in (-1, 0)]:
                solid.add((vertex[0] + d[0], vertex[1] + d[1], vertex[2] + d[2]))

    index = {}
    with open(sys.argv[3], "w") as out:
        out.write(f"# {sys.argv[1].split('/')[-1]} covered by cubes of side {size:.6g} "
                  f"({cells} along its longest side), made by voxel_control_mesh.py\n")
        for quad in quads:
            for vertex in quad:
                if vertex not in index:
                    index[vertex] = len(index)
                    out.write("v %.6f %.6f %.6f\n" % tuple(low[k] + (vertex[k] - 1) * size for k in range(3)))
        for quad in quads:
            out.write("f " + " ".join(str(index[v] + 1) for v in quad) + "\n")
    edges = 2 * len(quads)  # every quad has 4 edges, each shared by two quads
    genus = (2 - (len(index) - edges + len(quads))) // 2
    print(f"{len(index)} vertices, {len(quads)} quads, genus {genus}")


if __name__ == "__main__":
    main()
