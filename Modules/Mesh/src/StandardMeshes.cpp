#include "dynsub/StandardMeshes.h"

#include <array>
#include <cmath>
#include <map>

#include "dynsub/Error.h"

namespace dynsub {

ControlMesh makeCube98() {
  // Vertices are the points of the integer lattice {0..4}^3 on the cube's
  // surface, mapped to [-1, 1]^3; the map merges the points sides share.
  constexpr int n = 4;
  std::map<std::array<int, 3>, int> index;
  std::vector<Vector3> points;
  auto vertex = [&](std::array<int, 3> lattice) {
    auto [it, inserted] = index.emplace(lattice, static_cast<int>(points.size()));
    if (inserted) points.emplace_back(-1.0 + 2.0 * lattice[0] / n, -1.0 + 2.0 * lattice[1] / n,
                                      -1.0 + 2.0 * lattice[2] / n);
    return it->second;
  };
  std::vector<Polygon> faces;
  for (int a = 0; a < 3; ++a) {
    const int b = (a + 1) % 3;
    const int c = (a + 2) % 3;
    for (int side : {0, n}) {
      for (int p = 0; p < n; ++p) {
        for (int q = 0; q < n; ++q) {
          Polygon face;
          for (auto [dp, dq] : {std::pair{0, 0}, {1, 0}, {1, 1}, {0, 1}}) {
            std::array<int, 3> lattice{};
            lattice[a] = side;
            lattice[b] = p + dp;
            lattice[c] = q + dq;
            face.push_back(vertex(lattice));
          }
          // (b, c, a) is right-handed, so this order faces +a; the side at 0 faces -a.
          if (side == 0) std::reverse(face.begin(), face.end());
          faces.push_back(face);
        }
      }
    }
  }
  MatrixX3 matrix(points.size(), 3);
  for (size_t i = 0; i < points.size(); ++i) matrix.row(i) = points[i].transpose();
  return ControlMesh::fromPolygons(matrix, faces, "cube (98 vertices)");
}

ControlMesh makeTorus32() {
  constexpr int around = 8;   // along the major circle
  constexpr int section = 4;  // along the minor circle
  constexpr double majorRadius = 1.0;
  constexpr double minorRadius = 0.5;
  MatrixX3 points(around * section, 3);
  std::vector<Polygon> faces;
  auto id = [](int i, int j) { return (i % around) * section + (j % section); };
  for (int i = 0; i < around; ++i) {
    const double theta = 2.0 * M_PI * i / around;
    for (int j = 0; j < section; ++j) {
      const double phi = 2.0 * M_PI * j / section;
      const double radius = majorRadius + minorRadius * std::cos(phi);
      points.row(id(i, j)) << radius * std::cos(theta), radius * std::sin(theta), minorRadius * std::sin(phi);
      // d/dtheta x d/dphi points away from the tube's centre line: outward.
      faces.push_back({id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)});
    }
  }
  return ControlMesh::fromPolygons(points, faces, "torus (32 vertices)");
}

ControlMesh makeSheet81() {
  constexpr int n = 8;
  MatrixX3 points((n + 1) * (n + 1), 3);
  std::vector<Polygon> faces;
  auto id = [](int i, int j) { return j * (n + 1) + i; };
  for (int j = 0; j <= n; ++j) {
    for (int i = 0; i <= n; ++i) points.row(id(i, j)) << -1.0 + 2.0 * i / n, -1.0 + 2.0 * j / n, 0.0;
  }
  for (int j = 0; j < n; ++j) {
    for (int i = 0; i < n; ++i) faces.push_back({id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)});
  }
  return ControlMesh::fromPolygons(points, faces, "sheet (81 vertices)");
}

std::vector<std::string> standardMeshNames() { return {"cube", "torus", "sheet"}; }

ControlMesh makeStandardMesh(const std::string& name) {
  if (name == "cube") return makeCube98();
  if (name == "torus") return makeTorus32();
  if (name == "sheet") return makeSheet81();
  throw Error("unknown standard mesh '" + name + "' (expected cube, torus or sheet)");
}

}  // namespace dynsub
