// Unit tests: where a tessellated surface passes through itself.
#include <algorithm>
#include <set>

#include <gtest/gtest.h>

#include "TestMeshes.h"
#include "dynsub/SelfIntersection.h"
#include "dynsub/StandardMeshes.h"

namespace {

using dynsub::MatrixX3;
using dynsub::TriangleSurface;

// The output tessellation's density (kOutputSegments per element).
TriangleSurface outputTessellation(const dynsub::ControlMesh& mesh) {
  return dynsub::tessellate(dynsub::LimitSurface(mesh), mesh.points(), dynsub::kOutputSegments);
}

TEST(SelfIntersection, EmbeddedSurfacesHaveNone) {
  std::vector<dynsub::testing::NamedMesh> meshes = dynsub::testing::allTestMeshes();
  for (auto& creased : dynsub::testing::creasedTestMeshes()) meshes.push_back(std::move(creased));
  for (const auto& [name, mesh] : meshes) {
    const dynsub::SelfIntersection found = dynsub::findSelfIntersections(outputTessellation(mesh));
    EXPECT_EQ(found.trianglePairs, 0) << name;
    EXPECT_TRUE(found.triangles.empty()) << name;
    EXPECT_EQ(found.areaPercent, 0.0) << name;
  }
}

// The centre control vertex of the cube's +z side pushed through the -z side:
// the +z side's middle comes out below the -z side's.
TEST(SelfIntersection, FindsASidePushedThroughTheOther) {
  dynsub::ControlMesh cube = dynsub::makeCube98();
  MatrixX3 points = cube.points();
  int top = 0;
  for (int i = 1; i < points.rows(); ++i)
    if (points(i, 2) - points.row(i).head<2>().norm() > points(top, 2) - points.row(top).head<2>().norm()) top = i;
  ASSERT_EQ(points(top, 2), 1.0);
  ASSERT_EQ(points.row(top).head<2>().norm(), 0.0);
  points(top, 2) = -6.0;
  cube.setPoints(points);
  const TriangleSurface surface = outputTessellation(cube);
  const dynsub::SelfIntersection found = dynsub::findSelfIntersections(surface);
  EXPECT_GT(found.trianglePairs, 0);
  EXPECT_GT(found.areaPercent, 0.0);
  EXPECT_LT(found.areaPercent, 100.0);
  // Where the pushed middle passes the bottom: below the cube's centre, about the z axis.
  EXPECT_LT(found.boundsMax.z(), 0.0);
  EXPECT_LT(found.boundsMax.head<2>().norm(), 1.0);
  EXPECT_GT(found.boundsMin.head<2>().norm(), 0.0);
}

// A triangulated n x n grid of `size` squares on [0, 1]^2, mapped into 3D by `place`.
template <class Place>
void addGrid(TriangleSurface& surface, int n, Place place) {
  const int first = static_cast<int>(surface.points.rows());
  surface.points.conservativeResize(first + (n + 1) * (n + 1), 3);
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i) surface.points.row(first + j * (n + 1) + i) = place(double(i) / n, double(j) / n);
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const int a = first + j * (n + 1) + i, b = a + 1, c = a + n + 2, d = a + n + 1;
      surface.triangles.push_back({a, b, c});
      surface.triangles.push_back({a, c, d});
    }
}

// The interval of coordinate `along` where a triangle meets the plane `axis` = value.
std::pair<double, double> section(const TriangleSurface& s, int t, int axis, double value, int along) {
  double low = 1e300, high = -1e300;
  for (int k = 0; k < 3; ++k) {
    const dynsub::Vector3 p = s.points.row(s.triangles[t][k]), q = s.points.row(s.triangles[t][(k + 1) % 3]);
    if ((p(axis) - value) * (q(axis) - value) > 0.0 || p(axis) == q(axis)) continue;
    const double x = p(along) + (value - p(axis)) / (q(axis) - p(axis)) * (q(along) - p(along));
    low = std::min(low, x), high = std::max(high, x);
  }
  return {low, high};
}

// Two grids that cross along a known line: the plane z = 0 (10 x 10 squares on
// [0, 1]^2) and the plane x = 0.37 (7 x 7 squares, y in [-0.215, 1.185], z in
// [-0.45, 0.95], so that no sample lies on the other plane or touches its edges). The crossing triangles, their
// pairs and their bounds follow from the line alone.
TEST(SelfIntersection, FindsExactlyTheTrianglesAlongACrossingLine) {
  TriangleSurface s;
  s.points.resize(0, 3);
  addGrid(s, 10, [](double u, double v) { return dynsub::Vector3(u, v, 0.0); });
  const int horizontal = static_cast<int>(s.triangles.size());
  addGrid(s, 7, [](double u, double v) { return dynsub::Vector3(0.37, -0.215 + 1.4 * u, -0.45 + 1.4 * v); });

  const dynsub::SelfIntersection found = dynsub::findSelfIntersections(s);
  // Which triangles cross and how many pairs: each triangle's section by the
  // other plane is an interval along y; two triangles cross where theirs overlap.
  std::set<int> expected;
  int pairs = 0;
  for (int h = 0; h < horizontal; ++h) {
    const auto a = section(s, h, 0, 0.37, 1);
    for (int v = horizontal; v < static_cast<int>(s.triangles.size()); ++v) {
      const auto b = section(s, v, 2, 0.0, 1);
      if (std::max(a.first, b.first) < std::min(a.second, b.second)) {
        ++pairs;
        expected.insert(h);
        expected.insert(v);
      }
    }
  }
  // The column of squares x in [0.3, 0.4] (20 triangles), and the row of the
  // vertical grid that holds z = 0 (z in [-0.05, 0.15]) where it meets y in [0, 1].
  ASSERT_GT(pairs, 20);
  EXPECT_EQ(found.trianglePairs, pairs);
  EXPECT_EQ(std::set<int>(found.triangles.begin(), found.triangles.end()), expected);
  int column = 0;
  for (int t : found.triangles) column += t < horizontal;
  EXPECT_EQ(column, 20);
  EXPECT_NEAR(found.boundsMin.x(), 0.3, 1e-12);
  EXPECT_NEAR(found.boundsMax.x(), 0.4, 1e-12);
  EXPECT_NEAR(found.boundsMin.z(), -0.05, 1e-12);
  EXPECT_NEAR(found.boundsMax.z(), 0.15, 1e-12);
  // The horizontal grid's 20 triangles are 0.1 of its area 1; the vertical ones found, 0.02 each of 1.96.
  const double vertical = static_cast<double>(found.triangles.size()) - 20;
  EXPECT_NEAR(found.areaPercent, 100.0 * (0.1 + 0.02 * vertical) / 2.96, 1e-9);
}

// A long triangle through a fine grid far smaller than it: the grid's
// 9,800 triangles (70 x 70 squares of 1e-4 on z = 0.0035) make the cells about
// a thousandth of the box, whose 1000^3 cells the long triangle's box meets.
// It crosses the grid along a line: exactly the grid triangles with corners on
// both sides of that line cross it, each in one pair.
TEST(SelfIntersection, FindsALongTriangleThroughAFineGrid) {
  TriangleSurface s;
  s.points.resize(0, 3);
  const double height = 0.0035;
  addGrid(s, 70, [&](double u, double v) { return dynsub::Vector3(0.007 * u, 0.007 * v, height); });
  const int grid = static_cast<int>(s.triangles.size());
  // The line through q along d (no grid sample on it), and a direction w out of
  // the grid's plane: the triangle's corners at (-2, -1), (2, -1) and (0, 1.5)
  // in (d, w), so that its section by z = height runs 1.2 along d each way, far
  // past the grid.
  const dynsub::Vector3 q(0.00313, 0.00171, height), d(0.8, 0.6, 0.0), w(-0.18, 0.24, 1.0);
  const int first = static_cast<int>(s.points.rows());
  s.points.conservativeResize(first + 3, 3);
  s.points.row(first) = q - 2.0 * d - w;
  s.points.row(first + 1) = q + 2.0 * d - w;
  s.points.row(first + 2) = q + 1.5 * w;
  s.triangles.push_back({first, first + 1, first + 2});

  std::vector<int> expected;
  for (int t = 0; t < grid; ++t) {
    double low = 1e300, high = -1e300;
    for (int k = 0; k < 3; ++k) {
      const dynsub::Vector3 offset = s.points.row(s.triangles[t][k]).transpose() - q;
      const double side = offset.x() * d.y() - offset.y() * d.x();
      low = std::min(low, side), high = std::max(high, side);
    }
    if (low < 0.0 && high > 0.0) expected.push_back(t);
  }
  ASSERT_GT(expected.size(), 100u);
  const dynsub::SelfIntersection found = dynsub::findSelfIntersections(s);
  EXPECT_EQ(found.trianglePairs, static_cast<int>(expected.size()));
  expected.push_back(grid);
  EXPECT_EQ(found.triangles, expected);
}

TEST(SelfIntersection, AnEmptySurfaceHasNone) {
  TriangleSurface s;
  s.points.resize(0, 3);
  EXPECT_EQ(dynsub::findSelfIntersections(s).trianglePairs, 0);
}

}  // namespace
