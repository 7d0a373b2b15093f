// Expert-like clicks made from a labelmap (ClickProtocol.h), on a voxelized
// ball whose boundary is known exactly.
#include <gtest/gtest.h>

#include <cmath>
#include <set>

#include "dynsub/ClickProtocol.h"
#include "dynsub/Error.h"

namespace dynsub {
namespace {

// A ball of radius 10 mm on a 1 mm grid, its centre at a voxel centre.
struct Ball {
  Mask mask;
  Vector3 centre;
  double radius = 10.0;
};

Ball makeBall() {
  Ball ball;
  ImageGeometry& g = ball.mask.geometry;
  g.size = {31, 31, 31};
  g.origin = Vector3(-15, -15, -15);
  ball.centre = Vector3::Zero();
  ball.mask.voxels.assign(g.voxelCount(), 0);
  for (int k = 0; k < 31; ++k)
    for (int j = 0; j < 31; ++j)
      for (int i = 0; i < 31; ++i)
        ball.mask.voxels[g.offset(i, j, k)] = (g.toPhysical(Vector3(i, j, k)) - ball.centre).norm() <= ball.radius;
  return ball;
}

double offBoundary(const Ball& ball, const Vector3& p) { return std::abs((p - ball.centre).norm() - ball.radius); }

TEST(ClickProtocol, ClicksLieOnTheBoundaryOfTheChosenSlices) {
  const Ball ball = makeBall();
  ClickProtocol protocol;
  protocol.axis = 1;
  protocol.slices = 5;
  protocol.pointsPerSlice = 6;
  protocol.scatter = 0.0;
  const std::vector<Landmark> clicks = expertClicks(ball.mask, protocol, 7);
  ASSERT_EQ(clicks.size(), 30u);
  std::set<double> planes;
  for (const Landmark& c : clicks) {
    // Boundary midpoints of a voxelized ball lie within about a voxel's
    // half-diagonal (0.87 mm) of the true sphere.
    EXPECT_LT(offBoundary(ball, c.position), 0.87) << c.label;
    EXPECT_EQ(c.position.y(), std::round(c.position.y())) << "a click left its slice";
    planes.insert(c.position.y());
  }
  EXPECT_EQ(planes.size(), 5u);
  // The slices span at most 80 % of the ball's 21-voxel extent, so its ends go unclicked.
  EXPECT_LE(*planes.rbegin() - *planes.begin(), 0.8 * 21);
  EXPECT_GT(*planes.begin(), -10.5);
  EXPECT_LT(*planes.rbegin(), 10.5);
}

TEST(ClickProtocol, TheSeedDecidesEverything) {
  const Ball ball = makeBall();
  ClickProtocol protocol;
  const auto a = expertClicks(ball.mask, protocol, 3), b = expertClicks(ball.mask, protocol, 3),
             c = expertClicks(ball.mask, protocol, 4);
  ASSERT_EQ(a.size(), b.size());
  double same = 0, different = 0;
  for (size_t i = 0; i < a.size(); ++i) same += (a[i].position - b[i].position).norm();
  for (size_t i = 0; i < std::min(a.size(), c.size()); ++i) different += (a[i].position - c[i].position).norm();
  EXPECT_EQ(same, 0.0);
  EXPECT_GT(different, 1.0);
}

TEST(ClickProtocol, ScatterStaysInTheSliceAndMistakesLeaveTheBoundary) {
  const Ball ball = makeBall();
  ClickProtocol protocol;
  protocol.axis = 2;
  protocol.scatter = 0.4;
  protocol.mistakes = 3;
  protocol.mistakeDistance = 4.0;
  const std::vector<Landmark> clicks = expertClicks(ball.mask, protocol, 11);
  int off = 0;
  double scatter = 0;
  for (const Landmark& c : clicks) {
    EXPECT_EQ(c.position.z(), std::round(c.position.z())) << "scatter left the slice";
    const double d = offBoundary(ball, c.position);
    if (d > 2.5) {
      ++off;
    } else {
      scatter += d * d;
    }
  }
  EXPECT_EQ(off, 3) << "mistaken clicks 4 mm off the boundary";
  // 0.4 mm per in-plane axis gives up to ~0.57 mm off the boundary; with the
  // voxelization's own error, the rms stays well under a millimetre.
  EXPECT_LT(std::sqrt(scatter / (clicks.size() - off)), 1.0);
}

TEST(ClickProtocol, NoClickOnTheImagesSideOrBeyondIt) {
  // The ball cut by the image's side: its voxels up to x = +5 mm only, so the
  // slices across y meet the side at x = 5.5 (the last voxel's outer face),
  // where there is no edge to click; the boundary points beside that voxel lie
  // at x = 5. With 2 mm of scatter, clicks near the side would leave the image.
  Ball ball = makeBall();
  ImageGeometry& g = ball.mask.geometry;
  Mask cut;
  cut.geometry = g;
  cut.geometry.size = {21, 31, 31};
  cut.voxels.assign(cut.geometry.voxelCount(), 0);
  for (int k = 0; k < 31; ++k)
    for (int j = 0; j < 31; ++j)
      for (int i = 0; i < 21; ++i) cut.voxels[cut.geometry.offset(i, j, k)] = ball.mask.voxels[g.offset(i, j, k)];
  ClickProtocol protocol;
  protocol.axis = 1;
  protocol.slices = 6;
  protocol.pointsPerSlice = 8;
  for (const double scatter : {0.0, 2.0}) {
    protocol.scatter = scatter;
    for (unsigned seed = 1; seed <= 20; ++seed)
      for (const Landmark& c : expertClicks(cut, protocol, seed)) {
        EXPECT_TRUE(cut.geometry.covers(c.position)) << "seed " << seed << ", " << c.label << " beyond the image";
        if (scatter == 0.0) {
          EXPECT_LE(c.position.x(), 5.0) << "seed " << seed << ", " << c.label << " on the side";
        }
      }
  }
}

TEST(ClickProtocol, TheSeedClickIsDeepInside) {
  const Ball ball = makeBall();
  EXPECT_LT((seedClick(ball.mask) - ball.centre).norm(), 1.0);
  ClickProtocol seedOnly;
  seedOnly.seedOnly = true;
  EXPECT_TRUE(expertClicks(ball.mask, seedOnly, 1).empty());
  // Scattered: at least half the deepest (city-block) depth, 11 voxels at
  // the centre, so at least 6 steps along the axes from outside: a Euclidean
  // depth of 6 / sqrt(3) = 3.5 mm or more, about 6.5 mm at most from the centre of
  // the 10 mm ball. Seeded, and not all alike.
  std::vector<Vector3> clicks;
  for (unsigned seed = 1; seed <= 5; ++seed) {
    const Vector3 click = seedClick(ball.mask, 0.5, seed);
    EXPECT_LT((click - ball.centre).norm(), ball.radius - 6.0 / std::sqrt(3.0) + 0.5) << "seed " << seed;
    EXPECT_EQ((seedClick(ball.mask, 0.5, seed) - click).norm(), 0.0) << "seed " << seed;
    clicks.push_back(click);
  }
  EXPECT_GT((clicks[0] - clicks[1]).norm() + (clicks[0] - clicks[2]).norm(), 0.0);
  EXPECT_THROW(seedClick(ball.mask, 0.0, 1), Error);
}

TEST(ClickProtocol, ImpossibleProtocolsAreRefused) {
  const Ball ball = makeBall();
  ClickProtocol p;
  p.slices = 0;
  EXPECT_THROW(checkClickProtocol(p), Error);
  p = ClickProtocol();
  p.coverageLow = 0.9;
  p.coverageHigh = 0.5;
  EXPECT_THROW(checkClickProtocol(p), Error);
  p = ClickProtocol();
  p.pointsPerSlice = 100;  // more than the boundary has on a slice near the ball's end
  p.coverageLow = p.coverageHigh = 1.0;
  EXPECT_THROW(expertClicks(ball.mask, p, 1), Error);
  Mask empty = ball.mask;
  std::fill(empty.voxels.begin(), empty.voxels.end(), 0);
  EXPECT_THROW(expertClicks(empty, ClickProtocol(), 1), Error);
  EXPECT_THROW(seedClick(empty), Error);
  p = ClickProtocol();
  p.seedOnly = true;
  p.seedDepth = 1.5;
  EXPECT_THROW(checkClickProtocol(p), Error);
}

}  // namespace
}  // namespace dynsub
