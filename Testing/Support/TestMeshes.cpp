#include "TestMeshes.h"

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

}  // namespace dynsub::testing
