// Unit tests (no rendering): each defect is rejected with a message naming it.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "dynsub/ControlMesh.h"
#include "dynsub/Error.h"
#include "dynsub/MeshCheck.h"

namespace {

using dynsub::ControlMesh;
using dynsub::MatrixX3;
using dynsub::Polygon;

// Expects fromPolygons to throw an error whose message contains `fragment`.
void expectRejected(const MatrixX3& points, const std::vector<Polygon>& faces, const std::string& fragment) {
  try {
    ControlMesh::fromPolygons(points, faces, "test.obj");
    FAIL() << "accepted a mesh that should fail with: " << fragment;
  } catch (const dynsub::Error& error) {
    const std::string message = error.what();
    EXPECT_NE(message.find("test.obj"), std::string::npos) << message;
    EXPECT_NE(message.find(fragment), std::string::npos) << message;
  }
}

MatrixX3 gridPoints(int columns, int rows) {
  MatrixX3 points(columns * rows, 3);
  for (int j = 0; j < rows; ++j)
    for (int i = 0; i < columns; ++i) points.row(j * columns + i) << i, j, 0;
  return points;
}

TEST(MeshCheck, AcceptsAnOpenQuadGrid) {
  const ControlMesh mesh = ControlMesh::fromPolygons(gridPoints(3, 2), {{0, 1, 4, 3}, {1, 2, 5, 4}});
  EXPECT_EQ(mesh.vertexCount(), 6);
  EXPECT_EQ(mesh.faceCount(), 2);
  EXPECT_EQ(mesh.boundaryLoopCount(), 1);
  EXPECT_FALSE(mesh.isClosed());
}

TEST(MeshCheck, FacesKeepTheirVertexOrder) {
  const std::vector<Polygon> faces{{4, 3, 0, 1}, {1, 2, 5, 4}};
  const ControlMesh mesh = ControlMesh::fromPolygons(gridPoints(3, 2), faces);
  EXPECT_EQ(mesh.faces(), faces);
}

TEST(MeshCheck, RejectsEmptyMeshes) {
  expectRejected(MatrixX3(0, 3), {}, "no vertices");
  expectRejected(gridPoints(2, 2), {}, "no faces");
}

TEST(MeshCheck, RejectsBadFaces) {
  expectRejected(gridPoints(2, 2), {{0, 1}}, "at least 3");
  expectRejected(gridPoints(2, 2), {{0, 1, 7}}, "uses vertex 7");
  expectRejected(gridPoints(2, 2), {{0, 1, 1, 2}}, "twice");
  expectRejected(gridPoints(3, 1), {{0, 1, 2}}, "area is zero");
  // One vertex a million times farther than the rest leaves the unit
  // square no area beside the whole's extent: said so, not "area is zero".
  MatrixX3 far = gridPoints(3, 2);
  far.row(5) << 0.0, 0.0, 1e6;
  expectRejected(far, {{0, 1, 4, 3}, {1, 2, 5, 4}},
                 "face 0 is degenerate: its area, 1, is below 1e-12 of the square "
                 "of the whole's extent, 1e+06: is a point far from the others");
}

TEST(MeshCheck, RejectsNonFiniteCoordinates) {
  MatrixX3 points = gridPoints(2, 2);
  points(2, 1) = std::numeric_limits<double>::quiet_NaN();
  expectRejected(points, {{0, 1, 3, 2}}, "NaN");
}

TEST(MeshCheck, RejectsIsolatedVertices) {
  expectRejected(gridPoints(3, 2), {{0, 1, 4, 3}}, "vertex 2 is isolated");
}

TEST(MeshCheck, RejectsNonManifoldEdges) {
  MatrixX3 points(5, 3);
  points << 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, -1, 0, 0, 0, 1;
  expectRejected(points, {{0, 1, 2}, {1, 0, 3}, {0, 1, 4}}, "edge (0, 1) is shared by 3 faces");
}

TEST(MeshCheck, RejectsNonManifoldVertices) {
  // Two triangles touching at vertex 0 only (a bowtie).
  MatrixX3 points(5, 3);
  points << 0, 0, 0, 1, 0, 0, 1, 1, 0, -1, 0, 0, -1, -1, 0;
  expectRejected(points, {{0, 1, 2}, {0, 3, 4}}, "separate fans");
}

TEST(MeshCheck, RejectsInconsistentOrientation) {
  expectRejected(gridPoints(3, 2), {{0, 1, 4, 3}, {1, 4, 5, 2}},
                 "faces 0 and 1 both run along edge (1, 4) in the same direction: the orientation is inconsistent");
  // Of two such edges, the one met first in the faces' order is named: face
  // 2 runs along (4, 5) as face 0 does before it runs along (1, 4) as face 1
  // does, though (1, 4) is the lower edge.
  expectRejected(gridPoints(3, 3), {{4, 5, 8, 7}, {0, 1, 4, 3}, {4, 5, 2, 1}},
                 "faces 0 and 2 both run along edge (4, 5)");
  // The edge is named the way the faces run along it.
  expectRejected(gridPoints(3, 3), {{0, 1, 4, 3}, {4, 3, 6, 7}}, "faces 0 and 1 both run along edge (4, 3)");
}

// A bipyramid: apexes 0 and 1 over a ring of `ring` vertices, each apex with
// `ring` triangles around it.
std::vector<Polygon> bipyramidFaces(int ring) {
  std::vector<Polygon> faces;
  for (int i = 0; i < ring; ++i) {
    const int a = 2 + i, b = 2 + (i + 1) % ring;
    faces.push_back({0, a, b});
    faces.push_back({1, b, a});
  }
  return faces;
}

MatrixX3 bipyramidPoints(int ring) {
  MatrixX3 points(ring + 2, 3);
  points.row(0) << 0, 0, 1;
  points.row(1) << 0, 0, -1;
  for (int i = 0; i < ring; ++i) {
    const double angle = 2.0 * M_PI * i / ring;
    points.row(2 + i) << std::cos(angle), std::sin(angle), 0;
  }
  return points;
}

TEST(MeshCheck, RejectsVerticesOfMoreFacesThanSupported) {
  const int most = dynsub::kLargestValence;
  EXPECT_EQ(ControlMesh::fromPolygons(bipyramidPoints(most), bipyramidFaces(most)).vertexCount(), most + 2);
  expectRejected(bipyramidPoints(most + 1), bipyramidFaces(most + 1),
                 "vertex 0 has " + std::to_string(most + 1) + " faces around it; at most " + std::to_string(most));
}

}  // namespace
