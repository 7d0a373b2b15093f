// The coverage of a surface by a scan (SurfaceCoverage.h) on a flat square
// whose covered part is known: points on its left half leave its right half,
// beyond the margin, uncovered; points spread over a mesh's faces cover the
// whole face and stay in it.
#include <cmath>

#include <gtest/gtest.h>

#include "dynsub/Error.h"
#include "dynsub/SurfaceCoverage.h"

namespace dynsub {
namespace {

// The unit square z = 0 as a grid of n x n squares of two triangles each.
TriangleSurface square(int n) {
  TriangleSurface s;
  s.points.resize((n + 1) * (n + 1), 3);
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i) s.points.row(j * (n + 1) + i) << double(i) / n, double(j) / n, 0.0;
  for (int j = 0; j < n; ++j) {
    for (int i = 0; i < n; ++i) {
      const int a = j * (n + 1) + i;
      s.triangles.push_back({a, a + 1, a + n + 2});
      s.triangles.push_back({a, a + n + 2, a + n + 1});
    }
  }
  return s;
}

// Grid points spacing apart on the part of the unit square with x <= xMax.
MatrixX3 gridPoints(double spacing, double xMax) {
  const int columns = static_cast<int>(xMax / spacing + 1e-9) + 1, rows = static_cast<int>(1.0 / spacing + 1e-9) + 1;
  MatrixX3 points(columns * rows, 3);
  for (int j = 0; j < rows; ++j)
    for (int i = 0; i < columns; ++i) points.row(j * columns + i) << i * spacing, j * spacing, 0.0;
  return points;
}

TEST(SurfaceCoverage, PointsOverTheWholeSurfaceCoverIt) {
  const SurfaceCoverage c = measureSurfaceCoverage(square(100), gridPoints(0.02, 1.0), 0.0);
  EXPECT_NEAR(c.spacing, 0.02, 1e-12);
  EXPECT_EQ(c.uncoveredFraction, 0.0);
  EXPECT_LT(c.maxGap, 0.02);  // half a grid diagonal at most
}

TEST(SurfaceCoverage, SurfaceBeyondTheMarginIsUncovered) {
  // Points on x <= 0.5, 0.01 apart: vertices beyond x = 0.5 + 4 x 0.01 (plus
  // the max error) are uncovered. The vertices' areas are exact thirds of
  // their triangles, so the fraction is within one column of vertices
  // (1/200 of the area) of the strip's width.
  const TriangleSurface s = square(200);
  const MatrixX3 left = gridPoints(0.01, 0.5);
  const SurfaceCoverage c = measureSurfaceCoverage(s, left, 0.0);
  EXPECT_NEAR(c.spacing, 0.01, 1e-12);
  EXPECT_NEAR(c.uncoveredFraction, 1.0 - 0.54, 0.005);
  EXPECT_NEAR(c.maxGap, std::hypot(0.5, 0.005), 1e-12);  // from (1, 0.005) to (0.5, 0)
  const SurfaceCoverage withError = measureSurfaceCoverage(s, left, 0.1);
  EXPECT_NEAR(withError.uncoveredFraction, 1.0 - 0.64, 0.005);
  EXPECT_NEAR(withError.limit, kCoverageSpacings * 0.01 + 0.1, 1e-12);  // what the figures colour magenta from
  EXPECT_THROW(measureSurfaceCoverage(s, left.topRows(1), 0.0), Error);

  // Each point twice, as an export that did not merge them writes it: the
  // spacing is still the distance to the next point, not 0.
  MatrixX3 twice(2 * left.rows(), 3);
  twice << left, left;
  EXPECT_NEAR(measureSurfaceCoverage(s, twice, 0.0).spacing, 0.01, 1e-12);
}

TEST(SurfaceCoverage, MeshSamplesSpreadOverTheFacesAndStayInThem) {
  MatrixX3 corners(4, 3);
  corners << 0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0;
  const MatrixX3 samples = sampleMeshFaces(corners, {{0, 1, 2, 3}}, 2000);
  // Two triangles whose longest edges, the diagonal, are sqrt 2 long: h =
  // sqrt(2 x 2 / 2000), and ceil(sqrt(2) / h)^2 = 32^2 sub-triangles each.
  EXPECT_EQ(samples.rows(), 2 * 32 * 32);
  EXPECT_GE(samples.minCoeff(), 0.0);
  EXPECT_LE(samples.leftCols(2).maxCoeff(), 1.0);
  EXPECT_EQ(samples.col(2).cwiseAbs().maxCoeff(), 0.0);
  EXPECT_EQ(measureSurfaceCoverage(square(50), samples, 0.0).uncoveredFraction, 0.0);

  // A sliver beside a unit triangle: its share of the samples by area is
  // 0.1, so m = ceil(2 sqrt(0.1) + 1) = 2 and it gets 4, not the 19 x 19 that
  // h along its length would give.
  MatrixX3 two(4, 3);
  two << 0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1e-4, 0;
  const MatrixX3 few = sampleMeshFaces(two, {{0, 1, 2}, {0, 3, 1}}, 1000);
  EXPECT_EQ((few.col(1).array() < 1e-4).count(), 4);
  EXPECT_EQ(sampleMeshFaces(corners, {{0, 1, 1}}, 100).rows(), 0);  // no area
  EXPECT_EQ(sampleMeshFaces(corners, {{0, 1, 7}}, 100).rows(), 0);  // no such vertex
  EXPECT_THROW(sampleMeshFaces(corners, {{0, 1, 2}}, 0), Error);
}

}  // namespace
}  // namespace dynsub
