// Unit tests (no rendering): Catmull-Clark refinement and its matrix A.
#include <gtest/gtest.h>

#include "dynsub/CatmullClark.h"
#include "dynsub/StandardMeshes.h"

namespace {

TEST(CatmullClark, CubeRefinesToThePapersCounts) {
  const dynsub::SubdividedMesh refined = dynsub::subdivide(dynsub::makeCube98());
  // ICCV 1998 §4: 98 -> 386 vertices, 96 -> 384 faces.
  EXPECT_EQ(refined.mesh.vertexCount(), 386);
  EXPECT_EQ(refined.mesh.faceCount(), 384);
  EXPECT_EQ(refined.subdivisionMatrix.rows(), 386);
  EXPECT_EQ(refined.subdivisionMatrix.cols(), 98);
}

TEST(CatmullClark, RowsOfASumToOne) {
  for (const dynsub::ControlMesh& mesh : {dynsub::makeCube98(), dynsub::makeTorus32(), dynsub::makeSheet81()}) {
    const dynsub::SparseMatrix a = dynsub::subdivide(mesh).subdivisionMatrix;
    const Eigen::VectorXd sums = a * Eigen::VectorXd::Ones(a.cols());
    EXPECT_LE((sums.array() - 1.0).abs().maxCoeff(), 1e-15);
  }
}

TEST(CatmullClark, InteriorRulesOnTheCube) {
  const dynsub::ControlMesh cube = dynsub::makeCube98();
  const dynsub::SubdividedMesh refined = dynsub::subdivide(cube);
  const dynsub::MatrixX3 before = cube.points();
  const dynsub::MatrixX3 after = refined.mesh.points();
  // Old vertices keep their numbers; a valence-3 corner (F + 2R + 0 V)/3 with
  // its three neighbours at distance 0.5 along the axes and faces around it.
  for (int v = 0; v < cube.vertexCount(); ++v) {
    if (cube.topology().vertexEdges(v).size() != 3) continue;
    const dynsub::Vector3 corner = before.row(v).transpose();
    // Face points: centres of the 3 corner quads; edge midpoints: 0.25 along each axis.
    const dynsub::Vector3 inward = -corner.cwiseSign();
    dynsub::Vector3 f = dynsub::Vector3::Zero(), r = dynsub::Vector3::Zero();
    for (int a = 0; a < 3; ++a) {
      dynsub::Vector3 edge = corner;
      edge[a] += 0.25 * inward[a];
      r += edge / 3.0;
      dynsub::Vector3 face = corner;
      face[(a + 1) % 3] += 0.25 * inward[(a + 1) % 3];
      face[(a + 2) % 3] += 0.25 * inward[(a + 2) % 3];
      f += face / 3.0;
    }
    EXPECT_LE((after.row(v).transpose() - (f + 2.0 * r) / 3.0).norm(), 1e-15);
  }
}

TEST(CatmullClark, BoundaryRulesOnTheSheet) {
  dynsub::ControlMesh sheet = dynsub::makeSheet81();
  dynsub::MatrixX3 points = sheet.points();
  // Give the boundary a shape so the rules are visible in z.
  for (int v = 0; v < points.rows(); ++v) points(v, 2) = points(v, 0) * points(v, 0) + 0.5 * points(v, 1);
  sheet.setPoints(points);
  const dynsub::SubdividedMesh refined = dynsub::subdivide(sheet);
  const dynsub::MatrixX3 after = refined.mesh.points();
  auto id = [](int i, int j) { return j * 9 + i; };
  // Corner (valence 2) fixed.
  EXPECT_LE((after.row(id(0, 0)) - points.row(id(0, 0))).norm(), 1e-15);
  // Boundary vertex: 1/8, 3/4, 1/8 of its boundary neighbours.
  const Eigen::RowVector3d expected =
      0.125 * points.row(id(2, 0)) + 0.75 * points.row(id(3, 0)) + 0.125 * points.row(id(4, 0));
  EXPECT_LE((after.row(id(3, 0)) - expected).norm(), 1e-15);
  // Boundary edge point: the midpoint.
  const dynsub::Topology topology = sheet.topology();
  const int edge = topology.findEdge(id(3, 0), id(4, 0));
  ASSERT_GE(edge, 0);
  EXPECT_TRUE(topology.isBoundaryEdge(edge));
  EXPECT_LE((after.row(81 + edge) - 0.5 * (points.row(id(3, 0)) + points.row(id(4, 0)))).norm(), 1e-15);
}

TEST(CatmullClark, NgonsBecomeQuadsAroundTheirCentre) {
  dynsub::MatrixX3 points(5, 3);
  points << 1, 0, 0, 0.3, 0.95, 0, -0.8, 0.6, 0, -0.8, -0.6, 0, 0.3, -0.95, 0;
  const dynsub::ControlMesh pentagon = dynsub::ControlMesh::fromPolygons(points, {{0, 1, 2, 3, 4}});
  const dynsub::Refinement refinement = dynsub::refine(pentagon.topology());
  EXPECT_EQ(refinement.topology.faceCount(), 5);
  const int centre = 5 + 5;  // after 5 vertex points and 5 edge points
  for (int f = 0; f < 5; ++f) {
    EXPECT_EQ(refinement.topology.faceSize(f), 4);
    EXPECT_EQ(refinement.topology.face(f)[0], f);  // child k starts at old corner k
    EXPECT_EQ(refinement.topology.face(f)[2], centre);
  }
}

}  // namespace
