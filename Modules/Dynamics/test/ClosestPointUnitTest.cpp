// The closest-point locator against what it promises (ClosestPoint.h): its
// full search is at least as near as a dense tessellation, and tracking a
// moving surface with hints, on a sample tree it rebuilds only when needed,
// decides exactly as a locator whose tree is rebuilt at every state.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>
#include <string>

#include "dynsub/CatmullClark.h"
#include "dynsub/ClosestPoint.h"
#include "dynsub/LimitSurface.h"
#include "dynsub/StandardMeshes.h"
#include "dynsub/Tessellation.h"

namespace dynsub {
namespace {

// Points around the surface: tessellation points pushed along random
// directions by up to `spread` mm, plus a few far away.
MatrixX3 queriesAround(const LimitSurface& surface, const MatrixX3& controlPoints, double spread, unsigned seed) {
  const MatrixX3 near = tessellate(surface, controlPoints, 2).points;
  std::mt19937_64 random(seed);
  std::uniform_real_distribution<double> offset(-spread, spread);
  MatrixX3 queries(near.rows() + 4, 3);
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
    const MatrixX3 queries = queriesAround(surface, mesh.points(), 0.3, 5);
    // 32 x 32 segments per element: a far finer net than the locator's 6 x 6 samples.
    const MatrixX3 dense = tessellate(surface, mesh.points(), 32).points;
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

// Two samplings (the default 6 per element side, and 8): the decisions on an
// old tree check a share of the tree's samples (ClosestPoint.cpp), so which
// states they decide depends on the sample count; a shrunken ball fails at 8
// and not at 6.
TEST(ClosestPointLocator, TrackingDecidesAsARebuiltTreeDoes) {
  for (const int samples : {6, 8}) {
    for (const char* name : {"cube", "torus"}) {
      const ControlMesh mesh = makeStandardMesh(name);
      const LimitSurface surface(mesh);
      const MatrixX3 queries = queriesAround(surface, mesh.points(), 0.2, 9);
      ClosestPointLocator tracking(surface, samples);
      tracking.update(mesh.points());
      std::vector<ClosestPoint> last = tracking.findAll(queries);
      std::mt19937_64 random(3);
      std::normal_distribution<double> jitter(0.0, 0.002);
      MatrixX3 points = mesh.points();
      int moved = 0;
      for (int state = 1; state <= 40; ++state) {
        // Small moves per state (as in a fit's steps), with now and then a jump.
        const double scale = state % 10 == 0 ? 1.05 : 1.002;
        points *= scale;
        for (Eigen::Index v = 0; v < points.rows(); ++v)
          points.row(v) += Eigen::RowVector3d(jitter(random), jitter(random), jitter(random));
        tracking.update(points);
        ClosestPointLocator rebuilt(surface, samples);
        rebuilt.update(points);
        std::vector<ElementPoint> hints;
        for (const ClosestPoint& c : last) hints.push_back(c.point);
        const std::vector<ClosestPoint> tracked = tracking.findAll(queries, hints);
        const std::vector<ClosestPoint> reference = rebuilt.findAll(queries, hints);
        for (size_t i = 0; i < tracked.size(); ++i) {
          const std::string where = std::string(name) + " (" + std::to_string(samples) + " samples), state " +
                                    std::to_string(state) + ", query " + std::to_string(i);
          ASSERT_EQ(tracked[i].point.element, reference[i].point.element) << where;
          ASSERT_EQ(tracked[i].point.u, reference[i].point.u) << where;
          ASSERT_EQ(tracked[i].point.v, reference[i].point.v) << where;
          ASSERT_EQ(tracked[i].distance, reference[i].distance) << where;
          moved += tracked[i].point.element != last[i].point.element;
        }
        last = tracked;
      }
      EXPECT_GT(moved, 0) << name << ": no query changed element, so the search was never exercised";
    }
  }
}

// The stated accuracy (ClosestPoint.h): a query a short way off the surface
// along the limit normal at a known point has that point as its closest
// point, at that distance. Points inside elements of both kinds (normal ones,
// and special ones at the cube's valence-3 corners) on a 10 mm cube; the
// offset, 0.2 mm, is well inside the radius of curvature (about 5 mm), so the
// closest point is unique. The header promises the exact closest point to
// about 1e-8 of the element size (its diagonal); that is the tolerance.
TEST(ClosestPointLocator, FindsTheExactClosestPointToItsStatedAccuracy) {
  ControlMesh cube = makeStandardMesh("cube");
  cube.setPoints(cube.points() * 10.0);
  const LimitSurface surface(cube);
  ClosestPointLocator locator(surface);
  locator.update(cube.points());
  std::mt19937_64 random(7);
  std::uniform_real_distribution<double> parameter(0.05, 0.95);
  int special = 0;
  double worst = 0;
  for (int i = 0; i < 1000; ++i) {
    const ElementPoint at{static_cast<int>(random() % surface.elementCount()), parameter(random), parameter(random)};
    special += surface.elementType(at.element) == ElementType::Special;
    const double size = (surface.evaluate(ElementPoint{at.element, 1, 1}, cube.points()).position -
                         surface.evaluate(ElementPoint{at.element, 0, 0}, cube.points()).position)
                            .norm();
    const LimitSample sample = surface.evaluate(at, cube.points());
    for (const double offset : {0.2, -0.2}) {
      const ClosestPoint c = locator.find(sample.position + offset * sample.normal);
      const double error = std::max(std::abs(c.distance - 0.2), (c.position - sample.position).norm()) / size;
      worst = std::max(worst, error);
      EXPECT_LT(error, 1e-8) << "element " << at.element << " (" << at.u << ", " << at.v << ")";
    }
  }
  std::printf("worst error %.2e of the element size\n", worst);
  EXPECT_GT(special, 50);  // special elements were tried
}

// Samples of the once-refined surface are points of the original one: the
// locator finds them on it at distance zero (to Newton's stopping step).
TEST(ClosestPointLocator, FindsTheRefinedSurfacesSamplesOnTheOriginal) {
  for (const char* name : {"cube", "torus"}) {
    const ControlMesh mesh = makeStandardMesh(name);
    const SubdividedMesh refined = subdivide(mesh);
    const LimitSurface coarse(mesh), fine(refined.mesh);
    const TriangleSurface samples = tessellate(fine, refined.mesh.points(), 3);
    ClosestPointLocator locator(coarse, 8, 8);
    locator.update(mesh.points());
    double worst = 0.0;
    for (const ClosestPoint& c : locator.findAll(samples.points)) worst = std::max(worst, c.distance);
    // Exact in theory; Newton stops at steps of 1e-12 in parameters.
    EXPECT_LT(worst, 1e-9) << name;
  }
}

}  // namespace
}  // namespace dynsub
