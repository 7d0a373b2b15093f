// The smallest enclosing sphere (EnclosingSphere.h) against brute force.
#include <gtest/gtest.h>

#include <algorithm>
#include <random>

#include "TestPointClouds.h"
#include "dynsub/EnclosingSphere.h"

namespace dynsub {
namespace {

TEST(EnclosingSphere, MatchesBruteForce) {
  std::mt19937_64 random(11);
  std::uniform_real_distribution<double> coordinate(-1.0, 1.0);
  for (int trial = 0; trial < 5; ++trial) {
    const int n = 14;
    MatrixX3 points(n, 3);
    for (int i = 0; i < n; ++i) points.row(i) << coordinate(random), 2.0 * coordinate(random), coordinate(random);
    const Sphere s = smallestEnclosingSphere(points);
    for (int i = 0; i < n; ++i) EXPECT_LE((points.row(i).transpose() - s.center).norm(), s.radius * (1 + 1e-9));
    // The smallest sphere is determined by 2, 3 or 4 points on it: try them all.
    double best = std::numeric_limits<double>::infinity();
    auto consider = [&](const Vector3& c) {
      double r = 0.0;
      for (int i = 0; i < n; ++i) r = std::max(r, (points.row(i).transpose() - c).norm());
      best = std::min(best, r);
    };
    for (int a = 0; a < n; ++a) {
      for (int b = a + 1; b < n; ++b) {
        consider(0.5 * (points.row(a) + points.row(b)).transpose());
        for (int c = b + 1; c < n; ++c) {
          MatrixX3 three(3, 3);
          three << points.row(a), points.row(b), points.row(c);
          // The smallest sphere of 3 points, computed by the same routine, is their circle or a pair.
          consider(smallestEnclosingSphere(three).center);
          for (int d = c + 1; d < n; ++d) {
            Eigen::Matrix3d m;
            m << points.row(b) - points.row(a), points.row(c) - points.row(a), points.row(d) - points.row(a);
            const Vector3 rhs(0.5 * (points.row(b) - points.row(a)).squaredNorm(),
                              0.5 * (points.row(c) - points.row(a)).squaredNorm(),
                              0.5 * (points.row(d) - points.row(a)).squaredNorm());
            consider(points.row(a).transpose() + m.fullPivLu().solve(rhs));
          }
        }
      }
    }
    EXPECT_NEAR(s.radius, best, 1e-9 * best);
  }
}

TEST(EnclosingSphere, OfPointsOnASphere) {
  const MatrixX3 points = ellipsoidPoints(5000, Vector3(3.0, 3.0, 3.0), 3);
  const Sphere s = smallestEnclosingSphere(points);
  EXPECT_NEAR(s.radius, 3.0, 1e-3);  // 5000 random points leave no cap wider than ~0.05 rad uncovered
  EXPECT_LT(s.center.norm(), 2e-3);
}

}  // namespace
}  // namespace dynsub
