// The trust measures on shapes whose answers are known in closed form, and
// each flag raised by its own measure alone.
#include <cmath>

#include <gtest/gtest.h>

#include "dynsub/Trust.h"

namespace dynsub {
namespace {

// n points spread evenly over a sphere (a Fibonacci lattice).
std::vector<Vector3> spherePoints(int n, double radius) {
  std::vector<Vector3> points;
  const double golden = M_PI * (3.0 - std::sqrt(5.0));
  for (int i = 0; i < n; ++i) {
    const double z = 1.0 - (i + 0.5) * 2.0 / n, r = std::sqrt(1.0 - z * z);
    points.push_back(radius * Vector3(r * std::cos(golden * i), r * std::sin(golden * i), z));
  }
  return points;
}

TriangleSurface surfaceOf(const std::vector<Vector3>& points) {
  TriangleSurface s;
  s.points.resize(static_cast<Eigen::Index>(points.size()), 3);
  for (std::size_t i = 0; i < points.size(); ++i) s.points.row(static_cast<Eigen::Index>(i)) = points[i].transpose();
  return s;
}

bool has(const std::vector<TrustFlag>& flags, const std::string& name) {
  for (const TrustFlag& f : flags)
    if (f.name == name) return true;
  return false;
}

const double kBall = 4.0 / 3.0 * M_PI * 1000.0;  // a ball of radius 10 mm

// 24 clicks on each of the slices z = -8, -6, ..., 8 of a sphere of radius
// 10, and the volume their outlines give: each slice's regular 24-gon (area
// 12 r^2 sin(pi / 12)), joined by the trapezoid rule.
TrustEvidence clicksOnSlices(double* outlined) {
  TrustEvidence e;
  e.sliceNormal = Vector3::UnitZ();
  e.onSlice = 0.25;
  *outlined = 0;
  double previous = 0;
  for (int z = -8; z <= 8; z += 2) {
    const double r2 = 100.0 - z * z, area = 12 * r2 * std::sin(M_PI / 12);
    for (int k = 0; k < 24; ++k)
      e.clicks.emplace_back(std::sqrt(r2) * std::cos(k * M_PI / 12), std::sqrt(r2) * std::sin(k * M_PI / 12), z);
    if (z > -8) *outlined += (previous + area);  // times the 2 mm gap / 2
    previous = area;
  }
  return e;
}

TEST(Trust, ClicksOnSlicesOutlineTheirVolume) {
  double outlined = 0;
  TrustEvidence e = clicksOnSlices(&outlined);
  e.march = 6.0;  // against the 16 mm between the outermost clicked slices
  const TriangleSurface result = surfaceOf(spherePoints(20000, 10.0));
  const TrustMeasures m = measureTrust(result, kBall, e);
  EXPECT_NEAR(m.volumeRatio, kBall / outlined, 1e-9);
  // The ball beyond z = +-8 adds its caps: the ratio lies above 1.
  EXPECT_GT(m.volumeRatio, 1.05);
  // The farthest points are the poles, sqrt(6^2 + 2^2) mm from the clicks on
  // z = +-8; the lattice's point nearest a pole lies within 0.1 mm of it.
  EXPECT_NEAR(m.farthestFromEvidence, std::sqrt(40.0), 0.1);
  EXPECT_DOUBLE_EQ(m.marchShare, 6.0 / 16.0);
  EXPECT_TRUE(std::isnan(m.outlineDistance));
  EXPECT_TRUE(std::isnan(m.clicksToAtlas));
  EXPECT_TRUE(trustFlags(m, e).empty());
  // Clicks that are not on slices outline no volume.
  e.sliceNormal = Vector3::Zero();
  EXPECT_TRUE(std::isnan(measureTrust(result, kBall, e).volumeRatio));
}

TEST(Trust, ASurfaceFarFromSixClicksIsMeasuredExactly) {
  TrustEvidence e;
  for (int a = 0; a < 3; ++a)
    for (double sign : {-1.0, 1.0}) e.clicks.push_back(sign * 10.0 * Vector3::Unit(a));
  const TrustMeasures m = measureTrust(surfaceOf(spherePoints(20000, 10.0)), kBall, e);
  // The farthest points lie along the diagonals: the chord to an axis is
  // 2 r sin(acos(1 / sqrt 3) / 2) = 9.194 mm; the lattice's spacing (0.25
  // mm) puts its nearest point within 0.1 mm of that.
  EXPECT_NEAR(m.farthestFromEvidence, 9.194, 0.1);
}

TEST(Trust, EachFlagComesFromItsOwnMeasure) {
  const TriangleSurface result = surfaceOf(spherePoints(20000, 10.0));
  {  // shrunk to 40 % of what the clicks outline
    double outlined = 0;
    const TrustEvidence e = clicksOnSlices(&outlined);
    const std::vector<TrustFlag> flags = trustFlags(measureTrust(result, 0.4 * outlined, e), e);
    ASSERT_EQ(flags.size(), 1u);
    EXPECT_EQ(flags[0].name, "small");
    EXPECT_NE(flags[0].message.find("40 % of the volume of the outlines the clicks' slices give"), std::string::npos)
        << flags[0].message;
  }
  {  // an atlas's structure: its volume is the reference, its outline 5 mm off the result
    TrustEvidence e;
    e.outline = spherePoints(100, 15.0);
    e.volume = kBall;
    const TrustMeasures m = measureTrust(result, kBall, e);
    EXPECT_DOUBLE_EQ(m.volumeRatio, 1.0);
    // Each outline point's nearest result point: radially 5 mm, and at most
    // half the lattice's 0.25 mm spacing aside.
    EXPECT_NEAR(m.outlineDistance, 5.0, 0.01);
    const std::vector<TrustFlag> flags = trustFlags(m, e);
    ASSERT_EQ(flags.size(), 1u);
    EXPECT_EQ(flags[0].name, "moved_from_atlas");
  }
  {  // clicks apart from the atlas: the 90th percentile of ten distances is the ninth
    TrustEvidence e;
    e.volume = kBall;
    for (int i = 1; i <= 10; ++i) e.clicksToAtlas.push_back(i <= 8 ? 1.0 : 12.0 + i);
    const TrustMeasures m = measureTrust(result, kBall, e);
    EXPECT_DOUBLE_EQ(m.clicksToAtlas, 21.0);
    EXPECT_TRUE(has(trustFlags(m, e), "atlas_clicks_apart"));
    e.clicksToAtlas[8] = 1.0;  // one far click of ten is not a tenth beyond
    EXPECT_FALSE(has(trustFlags(measureTrust(result, kBall, e), e), "atlas_clicks_apart"));
  }
  {  // a click inside that moved the atlas's structure: 2 mm is a click near
     // its boundary, 22 mm one in the other hemisphere (RAS read as LPS)
    TrustEvidence e;
    e.volume = kBall;
    e.insideShift = 2.0;
    EXPECT_TRUE(trustFlags(measureTrust(result, kBall, e), e).empty());
    e.insideShift = 4.0;  // the threshold itself: not beyond it
    EXPECT_TRUE(trustFlags(measureTrust(result, kBall, e), e).empty());
    e.insideShift = 4.1;
    EXPECT_TRUE(has(trustFlags(measureTrust(result, kBall, e), e), "moved_to_click"));
    e.insideShift = 22.0;
    const TrustMeasures m = measureTrust(result, kBall, e);
    EXPECT_DOUBLE_EQ(m.insideShift, 22.0);
    const std::vector<TrustFlag> flags = trustFlags(m, e);
    ASSERT_EQ(flags.size(), 1u);
    EXPECT_EQ(flags[0].name, "moved_to_click");
    EXPECT_NE(flags[0].message.find("moved 22.0 mm"), std::string::npos) << flags[0].message;
  }
  {  // one click and nothing else; a leak out of the region
    TrustEvidence e;
    e.oneClick = true;
    e.outsideRegion = e.leakedInImage = 0.2;
    const std::vector<TrustFlag> flags = trustFlags(measureTrust(result, kBall, e), e);
    EXPECT_TRUE(has(flags, "one_click"));
    EXPECT_TRUE(has(flags, "leaked"));
    EXPECT_EQ(flags.size(), 2u);
  }
  {  // a structure the image's side cuts is said to be, not to have leaked
    TrustEvidence e;
    e.outsideRegion = 0.2;  // most of it beyond the side
    e.leakedInImage = 0.01;
    e.atImageSide = 0.15;
    const std::vector<TrustFlag> flags = trustFlags(measureTrust(result, kBall, e), e);
    ASSERT_EQ(flags.size(), 1u);
    EXPECT_EQ(flags[0].name, "cut_by_image_side");
    EXPECT_NE(flags[0].message.find("15.0 %"), std::string::npos) << flags[0].message;
  }
  {  // four clicks outline no volume, but a surface that shrank from its start has collapsed
    TrustEvidence e;
    e.sliceNormal = Vector3::UnitZ();
    e.onSlice = 0.25;
    e.clicks = {{10, 0, -5}, {-10, 0, -5}, {0, 10, 5}, {0, -10, 5}};
    e.initialVolume = kBall;
    TrustMeasures m = measureTrust(result, 0.2 * kBall, e);
    EXPECT_TRUE(std::isnan(m.volumeRatio));
    EXPECT_DOUBLE_EQ(m.initialRatio, 0.2);
    const std::vector<TrustFlag> flags = trustFlags(m, e);
    ASSERT_EQ(flags.size(), 1u);
    EXPECT_EQ(flags[0].name, "collapsed");
    EXPECT_NE(flags[0].message.find("20 % of the initial model's volume"), std::string::npos) << flags[0].message;
    // Half the start's volume is segment()'s own threshold: not below it.
    EXPECT_TRUE(trustFlags(measureTrust(result, 0.5 * kBall, e), e).empty());
    // Without the start's volume there is nothing to measure.
    e.initialVolume = 0;
    m = measureTrust(result, 0.2 * kBall, e);
    EXPECT_TRUE(std::isnan(m.initialRatio));
    EXPECT_TRUE(trustFlags(m, e).empty());
  }
}

}  // namespace
}  // namespace dynsub
