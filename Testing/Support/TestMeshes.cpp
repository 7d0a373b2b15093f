#include "TestMeshes.h"

#include <algorithm>
#include <cmath>

#include "dynsub/StandardMeshes.h"

namespace dynsub::testing {

ControlMesh makeFan(int n, bool closed) {
  // Centre 0; spokes 1..s; diagonals between consecutive spokes.
  const int spokes = closed ? n : n + 1;
  const double sector = (closed ? 2.0 : 1.5) * M_PI / n;
  MatrixX3 points(1 + spokes + n, 3);
  points.row(0) << 0.0, 0.0, 0.3;
  auto bowl = [](double x, double y) { return 0.25 * (x * x + y * y) + 0.1 * x * y; };
  for (int i = 0; i < spokes; ++i) {
    const double angle = i * sector;
    const double x = std::cos(angle), y = std::sin(angle);
    points.row(1 + i) << x, y, bowl(x, y);
  }
  std::vector<Polygon> faces;
  for (int i = 0; i < n; ++i) {
    const double angle = (i + 0.5) * sector;
    const double x = 1.6 * std::cos(angle), y = 1.6 * std::sin(angle);
    points.row(1 + spokes + i) << x, y, bowl(x, y);
    faces.push_back({0, 1 + i, 1 + spokes + i, 1 + (i + 1) % spokes});
  }
  return ControlMesh::fromPolygons(points, faces, "fan");
}

ControlMesh makePrism(int n) {
  MatrixX3 points(2 * n, 3);
  for (int i = 0; i < n; ++i) {
    const double angle = 2.0 * M_PI * i / n;
    // Radii vary so the shape is not symmetric.
    const double r = 1.0 + 0.15 * std::cos(3.0 * angle);
    points.row(i) << r * std::cos(angle), r * std::sin(angle), -0.8;
    points.row(n + i) << 0.8 * r * std::cos(angle), 0.8 * r * std::sin(angle), 0.9;
  }
  std::vector<Polygon> faces;
  Polygon bottom, top;
  for (int i = 0; i < n; ++i) {
    bottom.push_back(n - 1 - i);  // seen from below: counter-clockwise
    top.push_back(n + i);
    faces.push_back({i, (i + 1) % n, n + (i + 1) % n, n + i});
  }
  faces.push_back(bottom);
  faces.push_back(top);
  return ControlMesh::fromPolygons(points, faces, "prism");
}

ControlMesh makePyramid() {
  MatrixX3 points(5, 3);
  points << -1, -1, 0, 1, -1, 0, 1, 1, 0, -1, 1, 0, 0.2, 0.1, 1.4;
  return ControlMesh::fromPolygons(points, {{3, 2, 1, 0}, {0, 1, 4}, {1, 2, 4}, {2, 3, 4}, {3, 0, 4}}, "pyramid");
}

ControlMesh makeTetrahedron() {
  MatrixX3 points(4, 3);
  points << 1, 1, 1, -1, -1, 1, -1, 1, -1, 1, -1, -1;
  return ControlMesh::fromPolygons(points, {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}}, "tetrahedron");
}

ControlMesh makeLShape() {
  constexpr int n = 4;  // 4 x 4 vertices, 3 x 3 quads
  MatrixX3 points(n * n, 3);
  for (int j = 0; j < n; ++j) {
    for (int i = 0; i < n; ++i) {
      const double x = i - 1.5, y = j - 1.5;
      points.row(j * n + i) << x, y, 0.2 * x * x - 0.15 * y * y + 0.05 * x * y;
    }
  }
  std::vector<Polygon> faces;
  for (int j = 0; j < n - 1; ++j) {
    for (int i = 0; i < n - 1; ++i) {
      if (i == n - 2 && j == n - 2) continue;  // removed: vertex (2, 2) keeps 3 faces
      faces.push_back({j * n + i, j * n + i + 1, (j + 1) * n + i + 1, (j + 1) * n + i});
    }
  }
  // Drop the now unused corner vertex (3, 3) = 15: it is last, so just trim.
  return ControlMesh::fromPolygons(points.topRows(n * n - 1), faces, "L shape");
}

ControlMesh makeBumpyTorus() {
  ControlMesh torus = makeTorus32();
  MatrixX3 points = torus.points();
  for (Eigen::Index v = 0; v < points.rows(); ++v) {
    points.row(v) *= 1.0 + 0.1 * std::sin(3.0 * points(v, 0) + 2.0 * points(v, 2));
  }
  torus.setPoints(points);
  return torus;
}

std::vector<NamedMesh> allTestMeshes() {
  std::vector<NamedMesh> meshes;
  meshes.push_back({"cube98", makeCube98()});
  meshes.push_back({"torus32", makeTorus32()});
  meshes.push_back({"sheet81", makeSheet81()});
  for (int n : {3, 5, 6, 8}) meshes.push_back({"fan" + std::to_string(n), makeFan(n, true)});
  for (int n : {3, 5}) meshes.push_back({"openfan" + std::to_string(n), makeFan(n, false)});
  for (int n : {5, 6, 8}) meshes.push_back({"prism" + std::to_string(n), makePrism(n)});
  meshes.push_back({"pyramid", makePyramid()});
  meshes.push_back({"tetrahedron", makeTetrahedron()});
  meshes.push_back({"lshape", makeLShape()});
  meshes.push_back({"bumpytorus", makeBumpyTorus()});
  return meshes;
}

namespace {

// Sets the sharpness of every edge for which `sharpness(a, b)` is positive.
template <class Rule>
ControlMesh withCreases(ControlMesh mesh, Rule sharpness) {
  std::vector<Crease> creases;
  for (int e = 0; e < mesh.edgeCount(); ++e) {
    const auto [a, b] = mesh.topology().edgeVertices(e);
    const double s = sharpness(a, b);
    if (s > 0.0) creases.push_back({a, b, s});
  }
  mesh.setCreases(creases, "test mesh");
  return mesh;
}

// A cube of 8 vertices with its corners moved off the cube, so that no face is planar.
ControlMesh makeCube8() {
  MatrixX3 points(8, 3);
  points << -1, -1, -1, 1, -1, -1, 1, 1, -1, -1, 1, -1, -1, -1, 1, 1, -1, 1, 1, 1, 1, -1, 1, 1;
  for (Eigen::Index v = 0; v < 8; ++v) points.row(v) *= 1.0 + 0.15 * std::sin(2.0 * v + 1.0);
  return ControlMesh::fromPolygons(
      points, {{0, 3, 2, 1}, {4, 5, 6, 7}, {0, 1, 5, 4}, {1, 2, 6, 5}, {2, 3, 7, 6}, {3, 0, 4, 7}}, "cube8");
}

}  // namespace

std::vector<NamedMesh> creasedTestMeshes() {
  constexpr double sharp = kInfiniteSharpness;
  std::vector<NamedMesh> meshes;
  meshes.push_back({"cube8sharp", withCreases(makeCube8(), [](int, int) { return sharp; })});
  // Top face's edges 1.5, one vertical edge 2 and one 0.5 (a dart at its lower end).
  meshes.push_back({"cube8semi", withCreases(makeCube8(), [](int a, int b) {
                      if (a >= 4 && b >= 4) return 1.5;
                      if (std::min(a, b) == 1 && std::max(a, b) == 5) return 2.0;
                      if (std::min(a, b) == 3 && std::max(a, b) == 7) return 0.5;
                      return 0.0;
                    })});
  // The 98-vertex cube (bent) with its twelve edges sharp, then semi-sharp (2.5).
  ControlMesh cube = makeCube98();
  MatrixX3 bent = cube.points();
  for (Eigen::Index v = 0; v < bent.rows(); ++v) bent.row(v) *= 1.0 + 0.1 * std::sin(2.0 * bent(v, 0) + bent(v, 1));
  const MatrixX3 lattice = cube.points();
  cube.setPoints(bent);
  // A cube edge joins two lattice points with two coordinates at +-1.
  auto onCubeEdge = [&lattice](int a, int b) {
    int shared = 0;
    for (int c = 0; c < 3; ++c) shared += std::abs(lattice(a, c)) == 1.0 && lattice(a, c) == lattice(b, c);
    return shared == 2;
  };
  meshes.push_back({"cube98sharp", withCreases(cube, [&](int a, int b) { return onCubeEdge(a, b) ? sharp : 0.0; })});
  meshes.push_back({"cube98semi", withCreases(cube, [&](int a, int b) { return onCubeEdge(a, b) ? 2.5 : 0.0; })});
  // The bumpy torus with one loop around its major circle sharp and another semi-sharp (2).
  const ControlMesh torus = makeBumpyTorus();
  meshes.push_back({"toruscreases", withCreases(torus, [](int a, int b) {
                      const int ja = a % 4, jb = b % 4;  // position around the minor circle (makeTorus32)
                      if (ja != jb) return 0.0;
                      return ja == 0 ? sharp : ja == 2 ? 2.0 : 0.0;
                    })});
  // The sheet, bent, with a sharp crease across it from boundary to boundary
  // and a semi-sharp one (0.5) crossing it.
  ControlMesh sheet = makeSheet81();
  MatrixX3 points = sheet.points();
  for (Eigen::Index v = 0; v < points.rows(); ++v) {
    points(v, 2) = 0.3 * std::abs(points(v, 1)) + 0.2 * points(v, 0) * points(v, 0);
  }
  sheet.setPoints(points);
  meshes.push_back({"sheetcrease", withCreases(sheet, [&points](int a, int b) {
                      if (points(a, 1) == 0.0 && points(b, 1) == 0.0) return sharp;
                      if (points(a, 0) == 0.25 && points(b, 0) == 0.25) return 0.5;
                      return 0.0;
                    })});
  // Triangles and an extraordinary apex with a semi-sharp base.
  meshes.push_back(
      {"pyramidsemi", withCreases(makePyramid(), [](int a, int b) { return a < 4 && b < 4 ? 2.0 : 0.0; })});
  return meshes;
}

}  // namespace dynsub::testing
