#include <gtest/gtest.h>

#include <cmath>

#include "TestGrids.h"
#include "dynsub/Error.h"
#include "dynsub/LandmarkConvention.h"

namespace dynsub {
namespace {

// Bright balls (radius 8 mm) on a dark background, in a head-sized grid
// centred on the origin with skewed axes: as structures on either side of
// a brain's midline are, or a structure on one side only.
Volume balls(const std::vector<Vector3>& centres) {
  const ImageGeometry g = grid({70, 60, 50}, Vector3(1.0, 1.1, 1.3), Vector3::Zero(), skewDirection());
  Volume v{g, std::vector<float>(g.voxelCount(), 20.0f)};
  const Vector3 middle = g.toPhysical(Vector3(34.5, 29.5, 24.5));
  v.geometry.origin -= middle;  // the grid's centre at (0, 0, 0) mm
  for (int k = 0; k < g.size[2]; ++k)
    for (int j = 0; j < g.size[1]; ++j)
      for (int i = 0; i < g.size[0]; ++i)
        for (const Vector3& c : centres)
          if ((v.geometry.toPhysical(Vector3(i, j, k)) - c).norm() < 8.0) v.voxels[g.offset(i, j, k)] = 100.0f;
  return v;
}

// 20 points on a ball's surface (a Fibonacci sphere), as clicks on its boundary.
MatrixX3 onBall(const Vector3& centre) {
  const int n = 20;
  MatrixX3 points(n, 3);
  for (int i = 0; i < n; ++i) {
    const double z = 1 - (2.0 * i + 1) / n, r = std::sqrt(1 - z * z), phi = i * M_PI * (3 - std::sqrt(5.0));
    points.row(i) = (centre + 8.0 * Vector3(r * std::cos(phi), r * std::sin(phi), z)).transpose();
  }
  return points;
}

const Vector3 kRightFront(-18, -12, 3);  // LPS: x < 0 is right, y < 0 anterior

TEST(LandmarkConvention, PointsOnTheEdgesAsReadAreNotMisread) {
  const Volume image = balls({kRightFront});
  const ConventionScores s = conventionScores(image, onBall(kRightFront), 1.0, 1.0);
  // The ball's edge (80 per voxel, smoothed over sigma = 1 mm) against a
  // flat background: its misreadings fall where the gradient is zero.
  EXPECT_GT(s.asRead.strength, 10.0);
  EXPECT_LT(s.flipped.strength, 1e-3 * s.asRead.strength);
  EXPECT_LT(s.mirrored.strength, 1e-3 * s.asRead.strength);
  // Points on a sphere: its PCA ellipsoid is the sphere, whose normals the
  // ball's gradient follows to within the grid's sampling (a few degrees).
  EXPECT_GT(s.asRead.alignment, 0.95);
  EXPECT_EQ(likelyMisreading(s), Misreading::None);
}

TEST(LandmarkConvention, FlippedAndMirroredPointsAreNamed) {
  const Volume image = balls({kRightFront});
  const MatrixX3 truth = onBall(kRightFront);
  const ConventionScores flipped = conventionScores(image, misread(truth, Misreading::Flipped), 1.0, 1.0);
  EXPECT_EQ(likelyMisreading(flipped), Misreading::Flipped);
  const ConventionScores truthScores = conventionScores(image, truth, 1.0, 1.0);  // a flip is its own inverse
  EXPECT_NEAR(flipped.flipped.strength, truthScores.asRead.strength, 1e-9);
  EXPECT_NEAR(flipped.flipped.alignment, truthScores.asRead.alignment, 1e-9);
  const ConventionScores mirrored = conventionScores(image, misread(truth, Misreading::Mirrored), 1.0, 1.0);
  EXPECT_EQ(likelyMisreading(mirrored), Misreading::Mirrored);
}

TEST(LandmarkConvention, AStructureAndItsMirrorTwinAreNotMisread) {
  // Left and right twins: the mirror lies on edges as strong as the points,
  // which is no reason to refuse them.
  const Volume image = balls({kRightFront, Vector3(18, -12, 3)});
  const ConventionScores s = conventionScores(image, onBall(kRightFront), 1.0, 1.0);
  EXPECT_NEAR(s.mirrored.strength, s.asRead.strength, 0.1 * s.asRead.strength);
  EXPECT_EQ(likelyMisreading(s), Misreading::None);
}

TEST(LandmarkConvention, APointOutsideTheImageScoresZero) {
  const Volume image = balls({kRightFront});
  MatrixX3 points = misread(onBall(kRightFront), Misreading::Flipped);
  points(0, 0) = 500;  // off the grid as read, and as flipped
  const ConventionScores s = conventionScores(image, points, 1.0, 1.0);
  EXPECT_EQ(s.asRead.strength, 0.0);
  EXPECT_EQ(s.flipped.strength, 0.0);
  EXPECT_EQ(likelyMisreading(s), Misreading::None);
}

TEST(LandmarkConvention, RefusesTooFewPointsAndImpossibleOptions) {
  const Volume image = balls({kRightFront});
  EXPECT_THROW(conventionScores(image, onBall(kRightFront).topRows(3), 1.0, 1.0), Error);
  EXPECT_THROW(conventionScores(image, onBall(kRightFront), 0.0, 1.0), Error);
  EXPECT_THROW(conventionScores(image, onBall(kRightFront), 1.0, std::nan("")), Error);
}

}  // namespace
}  // namespace dynsub
