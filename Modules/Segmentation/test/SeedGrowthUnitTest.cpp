// The region grown from one click (SeedGrowth.h) on images whose answer is
// known: a ball joined to a larger block by a thin tube of the same tissue,
// on isotropic and anisotropic grids, and a flat image where any growth leaks.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "dynsub/Error.h"
#include "dynsub/SeedGrowth.h"

namespace dynsub {
namespace {

constexpr double kPi = 3.14159265358979323846;
const Vector3 kBall(20, 30, 30);
constexpr double kRadius = 8.0;  // mm

// Intensity 100 (noise 2) in a ball of radius 8 mm at (20, 30, 30) mm, in a
// block x >= 45 mm, and in a tube of radius 1 mm along x joining them; 20
// elsewhere. The grid spans 0..70 x 0..60 x 0..60 mm.
Volume ballTubeBlock(const Vector3& spacing) {
  Volume v;
  ImageGeometry& g = v.geometry;
  g.spacing = spacing;
  g.size = {static_cast<int>(70 / spacing.x()) + 1, static_cast<int>(60 / spacing.y()) + 1,
            static_cast<int>(60 / spacing.z()) + 1};
  v.voxels.resize(g.voxelCount());
  std::mt19937 random(7);
  std::normal_distribution<double> noise(0.0, 2.0);
  for (int k = 0; k < g.size[2]; ++k)
    for (int j = 0; j < g.size[1]; ++j)
      for (int i = 0; i < g.size[0]; ++i) {
        const Vector3 p = g.toPhysical(Vector3(i, j, k));
        const bool ball = (p - kBall).norm() <= kRadius;
        const bool tube = p.x() >= kBall.x() && std::hypot(p.y() - kBall.y(), p.z() - kBall.z()) <= 1.0;
        const bool block = p.x() >= 45;
        v.voxels[g.offset(i, j, k)] = static_cast<float>((ball || tube || block ? 100.0 : 20.0) + noise(random));
      }
  return v;
}

double volumeOf(const Mask& m) { return m.count() * m.geometry.spacing.prod(); }

TEST(SeedGrowthTest, TheOpeningCutsTheTubeAndKeepsTheBall) {
  // Tolerances: a voxelized ball's volume is within a few % of 4/3 pi r^3 at
  // r / h = 8, and its boundary midpoints lie within half a voxel diagonal
  // (0.87 mm) of the sphere; 10 % and 1 mm leave room for the noise.
  for (const Vector3& spacing : {Vector3(1, 1, 1), Vector3(0.8, 1.0, 1.25)}) {
    SCOPED_TRACE("spacing " + std::to_string(spacing.x()) + " " + std::to_string(spacing.z()));
    const Volume image = ballTubeBlock(spacing);
    const SeedRegion region = growFromSeed(image, kBall + Vector3(2, -1, 1));
    EXPECT_NEAR(region.median, 100.0, 2.0);
    EXPECT_LT(region.low, 95.0);
    EXPECT_GT(region.high, 105.0);
    EXPECT_GT(region.low, 20.0);
    EXPECT_FALSE(region.touchesReach);
    EXPECT_TRUE(seedWarnings(region).empty());
    EXPECT_FALSE(probablyLeaked(region));
    EXPECT_NEAR(volumeOf(region.mask), 4.0 / 3.0 * kPi * std::pow(kRadius, 3), 0.1 * 4.0 / 3.0 * kPi * 512);
    EXPECT_GT(region.grownVoxels * spacing.prod(), 20000.0);  // the growth itself reached the block
    ASSERT_EQ(region.boundary.size(), 60u);
    for (const Landmark& point : region.boundary) EXPECT_NEAR((point.position - kBall).norm(), kRadius, 1.0);
  }
}

TEST(SeedGrowthTest, TheLeakGuardOpensWhatTheFirstGrowthLeakedThrough) {
  // Without an opening the growth runs down the tube into the block and
  // reaches the edge of its box; the guard grows again with a 1 mm opening,
  // which cuts the tube (radius 1 mm) and keeps the ball.
  SeedOptions options;
  options.opening = 0;
  options.reach = 30;
  const SeedRegion region = growFromSeed(ballTubeBlock(Vector3::Ones()), kBall, options);
  EXPECT_FALSE(region.touchesReach);
  EXPECT_GT(region.opening, 0.0);
  EXPECT_NEAR(volumeOf(region.mask), 4.0 / 3.0 * kPi * std::pow(kRadius, 3), 0.1 * 4.0 / 3.0 * kPi * 512);
}

TEST(SeedGrowthTest, AFlatImageLeaksAndSaysSo) {
  Volume flat;
  flat.geometry.size = {40, 40, 40};
  flat.voxels.assign(flat.geometry.voxelCount(), 50.0f);
  SeedOptions options;
  options.reach = 10;
  const SeedRegion region = growFromSeed(flat, Vector3(20, 20, 20), options);
  EXPECT_TRUE(region.touchesReach);
  ASSERT_EQ(seedWarnings(region).size(), 1u);
  EXPECT_NE(seedWarnings(region)[0].find("leaked"), std::string::npos);
}

TEST(SeedGrowthTest, ARegionThatOnlyTheLastFifthOfItsWindowJoinedToANeighbourIsWarnedOf) {
  // A ball (radius 7 mm) joined to a 20 mm block of the same tissue by a
  // bridge 3 mm in radius (the opening keeps it) whose intensity, 103, lies
  // in the window (100 +- 4 spreads of 0.8: 1 % of the image's range, the
  // ball being flat) but not in one 0.8 times as wide (+- 2.56). The region
  // stays inside its box, so only the narrower window's growth tells the leak.
  Volume image;
  image.geometry.size = {64, 64, 64};
  image.voxels.assign(image.geometry.voxelCount(), 20.0f);
  const Vector3 ball(20, 32, 32);
  for (int k = 0; k < 64; ++k)
    for (int j = 0; j < 64; ++j)
      for (int i = 0; i < 64; ++i) {
        float& v = image.voxels[image.geometry.offset(i, j, k)];
        const bool inBridge = i >= 25 && i <= 37 && std::hypot(j - 32.0, k - 32.0) <= 3.0;
        if (inBridge) v = 103.0f;
        if ((Vector3(i, j, k) - ball).norm() <= 7.0) v = 100.0f;
        if (i >= 36 && i <= 56 && j >= 22 && j <= 42 && k >= 22 && k <= 42) v = 100.0f;
      }
  const SeedRegion region = growFromSeed(image, ball);
  EXPECT_FALSE(region.touchesReach);
  const double ballVolume = 4.0 / 3.0 * kPi * std::pow(7.0, 3);
  EXPECT_GT(volumeOf(region.mask), 8000.0);  // the block came in
  EXPECT_NEAR(region.narrowerWindowVolume, ballVolume, 0.1 * ballVolume);
  EXPECT_TRUE(probablyLeaked(region));
  const std::vector<std::string> warnings = seedWarnings(region);
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_NE(warnings[0].find("leaked"), std::string::npos) << warnings[0];
  EXPECT_NE(warnings[0].find("a fifth narrower"), std::string::npos) << warnings[0];
}

TEST(SeedGrowthTest, BadClicksAndOptionsAreErrors) {
  const Volume image = ballTubeBlock(Vector3::Ones());
  EXPECT_THROW(growFromSeed(image, Vector3(-30, 0, 0)), Error);
  EXPECT_THROW(growFromSeed(image, Vector3(NAN, 0, 0)), Error);
  SeedOptions options;
  options.window = 0;
  EXPECT_THROW(growFromSeed(image, kBall, options), Error);
  options = SeedOptions();
  options.opening = -1;
  EXPECT_THROW(growFromSeed(image, kBall, options), Error);
  // An opening wider than the ball leaves nothing at the click.
  options = SeedOptions();
  options.opening = 12;
  EXPECT_THROW(growFromSeed(image, kBall, options), Error);
}

TEST(SeedGrowthTest, ASmallRegionIsWarnedOf) {
  // A ball of radius 4 mm (268 mm^3) is below the 524 mm^3 of kSmallSeedRegion.
  Volume image;
  image.geometry.size = {40, 40, 40};
  image.voxels.assign(image.geometry.voxelCount(), 20.0f);
  for (int k = 0; k < 40; ++k)
    for (int j = 0; j < 40; ++j)
      for (int i = 0; i < 40; ++i)
        if (Vector3(i - 20, j - 20, k - 20).norm() <= 4.0) image.voxels[image.geometry.offset(i, j, k)] = 100.0f;
  const SeedRegion region = growFromSeed(image, Vector3(20, 20, 20));
  EXPECT_FALSE(region.touchesReach);
  const std::vector<std::string> warnings = seedWarnings(region);
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_NE(warnings[0].find("collapse"), std::string::npos) << warnings[0];
}

}  // namespace
}  // namespace dynsub
