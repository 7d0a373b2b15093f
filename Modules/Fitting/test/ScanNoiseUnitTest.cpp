// A scan's own noise and outliers (ScanNoise.h) on seeded clouds whose noise
// and outliers are known: the noise is measured to within the spread of a
// median over a few thousand points, outliers scattered about the shape are
// found, and clean, curved, sparsely sampled points are not called outliers.
#include <algorithm>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "TestPointClouds.h"
#include "dynsub/Error.h"
#include "dynsub/ScanNoise.h"

namespace dynsub {
namespace {

MatrixX3 withNoise(MatrixX3 points, double sigma, unsigned seed) {
  std::mt19937_64 random(seed);
  std::normal_distribution<double> normal(0.0, sigma);
  for (Eigen::Index i = 0; i < points.rows(); ++i) {
    for (int a = 0; a < 3; ++a) points(i, a) += normal(random);
  }
  return points;
}

// `count` points uniform in the cube [-size, size]^3 whose distance from the
// sphere of `radius` about the origin is at least `gap`.
MatrixX3 scatteredOff(int count, double size, double radius, double gap, unsigned seed) {
  std::mt19937_64 random(seed);
  std::uniform_real_distribution<double> uniform(-size, size);
  MatrixX3 points(count, 3);
  for (int i = 0; i < count;) {
    const Vector3 p(uniform(random), uniform(random), uniform(random));
    if (std::abs(p.norm() - radius) >= gap) points.row(i++) = p.transpose();
  }
  return points;
}

TEST(NearestNeighbours, AreTheNearestOtherPointsInOrder) {
  MatrixX3 line(6, 3);
  for (int i = 0; i < 6; ++i) line.row(i) << i * i, 0, 0;  // 0 1 4 9 16 25
  const Eigen::MatrixXi n = nearestNeighbours(line, 2);
  EXPECT_EQ(n(0, 0), 1);
  EXPECT_EQ(n(0, 1), 2);
  EXPECT_EQ(n(3, 0), 2);  // 9: 4 is 5 away, 16 is 7
  EXPECT_EQ(n(3, 1), 4);
  EXPECT_EQ(n(5, 0), 4);
  EXPECT_THROW(nearestNeighbours(line, 6), Error);
}

TEST(WithoutRows, DropsTheRowsAsked) {
  MatrixX3 points(5, 3);
  for (int i = 0; i < 5; ++i) points.row(i).setConstant(i);
  const MatrixX3 kept = withoutRows(points, {0, 3});
  ASSERT_EQ(kept.rows(), 3);
  EXPECT_EQ(kept(0, 0), 1);
  EXPECT_EQ(kept(1, 0), 2);
  EXPECT_EQ(kept(2, 0), 4);
}

// Isotropic noise of sigma per coordinate is sigma along the normal. The
// lower quartile of 3000 |t| has a relative standard error of about 3.3 %;
// 10 % leaves room for the small curvature the quadrics do not follow.
// `surface` with `outliers` after it.
MatrixX3 withOutliers(const MatrixX3& surface, const MatrixX3& outliers) {
  MatrixX3 scan(surface.rows() + outliers.rows(), 3);
  scan << surface, outliers;
  return scan;
}

TEST(ScanNoise, MeasuresKnownNoiseOnCurvedSurfaces) {
  for (double sigma : {0.1, 0.3}) {
    const ScanNoise sphere = estimateScanNoise(withNoise(ellipsoidPoints(3000, Vector3(50, 50, 50), 7), sigma, 8));
    EXPECT_NEAR(sphere.sigma, sigma, 0.1 * sigma) << "sphere";
    const ScanNoise torus = estimateScanNoise(withNoise(torusPoints(3000, 40, 15, 9), sigma, 10));
    EXPECT_NEAR(torus.sigma, sigma, 0.1 * sigma) << "torus";
  }
}

// Without noise only the quadrics' misfit is left: on a 3:2:1 ellipsoid
// sampled at about 3 mm it is a small fraction of the spacing.
TEST(ScanNoise, CleanPointsHaveNearlyNoNoiseAndNoOutliers) {
  const ScanNoise clean = estimateScanNoise(ellipsoidPoints(3000, Vector3(60, 40, 20), 11));
  EXPECT_LT(clean.sigma, 0.05);
  EXPECT_TRUE(clean.outliers.empty()) << clean.outliers.size() << " outliers";
  // 300 points on a genus-0 ellipsoid: neighbourhoods span a sixth of it.
  const ScanNoise sparse = estimateScanNoise(ellipsoidPoints(300, Vector3(60, 40, 20), 12));
  EXPECT_TRUE(sparse.outliers.empty()) << sparse.outliers.size() << " outliers";
}

// A torus (radii 40 and 15 mm) sampled by 300 points, about 7 mm apart, as
// sparsely as a small mesh's vertices: 20 neighbours reach around a third of
// the tube, whose bending the quadrics cannot follow, and their scatter is
// that bending (it grows with the neighbourhood, and sigma is 0). With 0.5
// mm of noise on 1500 points the scatter is the noise's, whatever the
// neighbourhood, and sigma keeps it (within 20 %: the lower quartile of 1500
// |t| has a relative standard error of about 5 %, and the tube's bending
// still adds to it).
TEST(ScanNoise, SparseDetailIsShapeNotNoise) {
  const ScanNoise sparse = estimateScanNoise(torusPoints(300, 40, 15, 19));
  EXPECT_GT(sparse.scatter, kShapeGrowth * sparse.scatterFew);
  EXPECT_EQ(sparse.sigma, 0.0);
  const ScanNoise noisy = estimateScanNoise(withNoise(torusPoints(1500, 40, 15, 20), 0.5, 21));
  EXPECT_NEAR(noisy.sigma, 0.5, 0.1);
  EXPECT_EQ(noisy.sigma, noisy.scatter);
}

// A box's edges and corners are no noise. 900 points on a 60 mm cube: at
// the usual spacing of 2.6 mm, most points have neighbours across an edge,
// and their quadrics bend there (the median of |t| reads 0.12 mm of noise
// from the clean box). With 0.3 mm of noise on 3000 points the box reads
// 0.34 mm, as the median does: near the edges, where the noise hides which
// side a neighbour is on, some quadrics still bend; 20 %.
TEST(ScanNoise, EdgesAndCornersAreNotNoise) {
  const ScanNoise clean = estimateScanNoise(boxPoints(900, 30, 16));
  EXPECT_LT(clean.sigma, 0.01);
  const ScanNoise noisy = estimateScanNoise(withNoise(boxPoints(3000, 30, 17), 0.3, 18));
  EXPECT_NEAR(noisy.sigma, 0.3, 0.06);
}

// 3 % outliers at least 2 mm (6.7 sigma) off a sphere with 0.3 mm noise: at
// least 95 % are found (those within a few sigma of the surface's noisy
// points may not stand out), and at most 0.5 % of the surface's points are
// set aside with them.
TEST(ScanNoise, FindsScatteredOutliers) {
  const MatrixX3 surface = withNoise(ellipsoidPoints(3000, Vector3(50, 50, 50), 13), 0.3, 14);
  const MatrixX3 scan = withOutliers(surface, scatteredOff(90, 55, 50, 2.0, 15));
  const ScanNoise noise = estimateScanNoise(scan);
  int found = 0, wrong = 0;
  for (int i : noise.outliers) (i >= surface.rows() ? found : wrong) += 1;
  EXPECT_GE(found, 86) << "of 90 outliers";
  EXPECT_LE(wrong, 15) << "of 3000 surface points";
  EXPECT_NEAR(noise.sigma, 0.3, 0.03);
}

// Every point twice or three times (a file written twice, overlapping scans
// merged) measures as the points once: a copy is not a neighbour whose
// offset tells noise, and a clean point's copy does not make it an outlier.
// An outlier's copies are all outliers.
TEST(ScanNoise, CopiesOfAPointCountOnce) {
  const MatrixX3 surface = withNoise(ellipsoidPoints(1500, Vector3(50, 50, 50), 22), 0.3, 23);
  const MatrixX3 scan = withOutliers(surface, scatteredOff(45, 55, 50, 2.0, 24));
  const ScanNoise once = estimateScanNoise(scan);
  for (const int copies : {2, 3}) {
    const ScanNoise copied = estimateScanNoise(scan.replicate(copies, 1));
    EXPECT_EQ(copied.sigma, once.sigma) << copies << " copies";
    std::vector<int> expected;
    for (int k = 0; k < copies; ++k)
      for (const int i : once.outliers) expected.push_back(i + k * static_cast<int>(scan.rows()));
    std::sort(expected.begin(), expected.end());
    EXPECT_EQ(copied.outliers, expected) << copies << " copies";
  }
  // Fewer distinct points than a neighbourhood: nothing measured.
  const ScanNoise few = estimateScanNoise(surface.topRows(10).replicate(3, 1));
  EXPECT_EQ(few.sigma, 0.0);
  EXPECT_TRUE(few.outliers.empty());
}

TEST(ScanNoise, RefusesTooFewPoints) {
  EXPECT_THROW(estimateScanNoise(ellipsoidPoints(kNoiseNeighbours, Vector3(1, 1, 1), 1)), Error);
}

}  // namespace
}  // namespace dynsub
