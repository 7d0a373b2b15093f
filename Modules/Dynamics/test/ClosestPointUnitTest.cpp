// The closest-point locator against what it promises (ClosestPoint.h): its
// full search is at least as near as a dense tessellation, and tracking a
// moving surface with hints, on a sample tree it rebuilds only when needed,
// decides exactly as a locator whose tree is rebuilt at every state.
#include <gtest/gtest.h>

#include <random>

#include "dynsub/ClosestPoint.h"
#include "dynsub/LimitSurface.h"
#include "dynsub/StandardMeshes.h"
#include "dynsub/Tessellation.h"

namespace dynsub {
namespace {

// Points around the surface: tessellation points pushed along random
// directions by up to `spread` mm, plus a few far away.
Matrix3X queriesAround(const LimitSurface& surface, const Matrix3X& controlPoints, double spread, unsigned seed) {
  const Matrix3X near = tessellate(surface, controlPoints, 2).points;
  std::mt19937_64 random(seed);
  std::uniform_real_distribution<double> offset(-spread, spread);
  Matrix3X queries(near.rows() + 4, 3);
  for (Eigen::Index i = 0; i < near.rows(); ++i)
    queries.row(i) = near.row(i) + Eigen::RowVector3d(offset(random), offset(random), offset(random));
  for (int i = 0; i < 4; ++i) queries.row(near.rows() + i) = Eigen::RowVector3d(10.0 * (i + 1), -7.0, 3.0 * i);
  return queries;
}

TEST(ClosestPointLocator, IsAtLeastAsNearAsADenseTessellation) {
  for (const char* name : {"cube", "torus", "sheet"}) {
    const ControlMesh mesh = makeStandardMesh(name);
    const LimitSurface surface(mesh);
    ClosestPointLocator locator(surface);
    locator.update(mesh.points());
    const Matrix3X queries = queriesAround(surface, mesh.points(), 0.3, 5);
    // 32 x 32 segments per element: a far finer net than the locator's 6 x 6 samples.
    const Matrix3X dense = tessellate(surface, mesh.points(), 32).points;
    const std::vector<ClosestPoint> found = locator.findAll(queries);
    for (Eigen::Index i = 0; i < queries.rows(); ++i) {
      const double net = (dense.rowwise() - queries.row(i)).rowwise().norm().minCoeff();
      // The result is a point of the surface, so never nearer than the truth;
      // it must be no farther than the dense net's nearest point (1e-9 mm
      // covers Newton's stopping rule).
      EXPECT_LE(found[i].distance, net + 1e-9) << name << ", query " << i;
      const LimitSample at = surface.evaluate(found[i].point, mesh.points());
      EXPECT_LT((at.position - found[i].position).norm(), 1e-12) << name << ", query " << i;
      EXPECT_NEAR((at.position - queries.row(i).transpose()).norm(), found[i].distance, 1e-12);
    }
  }
}

TEST(ClosestPointLocator, TrackingDecidesAsARebuiltTreeDoes) {
  for (const char* name : {"cube", "torus"}) {
    const ControlMesh mesh = makeStandardMesh(name);
    const LimitSurface surface(mesh);
    const Matrix3X queries = queriesAround(surface, mesh.points(), 0.2, 9);
    ClosestPointLocator tracking(surface);
    tracking.update(mesh.points());
    std::vector<ClosestPoint> last = tracking.findAll(queries);
    std::mt19937_64 random(3);
    std::normal_distribution<double> jitter(0.0, 0.002);
    Matrix3X points = mesh.points();
    int moved = 0;
    for (int state = 1; state <= 40; ++state) {
      // Small moves per state (as in a fit's steps), with now and then a jump.
      const double scale = state % 10 == 0 ? 1.05 : 1.002;
      points *= scale;
      for (Eigen::Index v = 0; v < points.rows(); ++v)
        points.row(v) += Eigen::RowVector3d(jitter(random), jitter(random), jitter(random));
      tracking.update(points);
      ClosestPointLocator rebuilt(surface);
      rebuilt.update(points);
      std::vector<ElementPoint> hints;
      for (const ClosestPoint& c : last) hints.push_back(c.point);
      const std::vector<ClosestPoint> tracked = tracking.findAll(queries, hints);
      const std::vector<ClosestPoint> reference = rebuilt.findAll(queries, hints);
      for (size_t i = 0; i < tracked.size(); ++i) {
        ASSERT_EQ(tracked[i].point.element, reference[i].point.element) << name << ", state " << state << ", query " << i;
        ASSERT_EQ(tracked[i].point.u, reference[i].point.u) << name << ", state " << state << ", query " << i;
        ASSERT_EQ(tracked[i].point.v, reference[i].point.v) << name << ", state " << state << ", query " << i;
        ASSERT_EQ(tracked[i].distance, reference[i].distance) << name << ", state " << state << ", query " << i;
        moved += tracked[i].point.element != last[i].point.element;
      }
      last = tracked;
    }
    EXPECT_GT(moved, 0) << name << ": no query changed element, so the search was never exercised";
  }
}

}  // namespace
}  // namespace dynsub
