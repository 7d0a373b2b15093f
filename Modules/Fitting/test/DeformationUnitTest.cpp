// Modeling by forces (Deformation.h): stiff springs that raise a bump on the
// 98-vertex cube, held by anchors elsewhere, are met by refining only near
// the targets still too far, to the tolerance,
// with fewer free points than global refinement needs; soft springs, which
// no finer mesh brings closer, end the refinement early; without refinement
// the tolerance is reported unmet; a surface the springs fold through itself
// is reported; bad options are refused.
#include <cmath>
#include <vector>

#include <gtest/gtest.h>

#include "dynsub/Deformation.h"
#include "dynsub/Error.h"
#include "dynsub/LimitSurface.h"
#include "dynsub/StandardMeshes.h"

namespace dynsub {
namespace {

// 53 anchors that hold the cube's shape, on a 3 x 3 grid at +-0.5 and 0
// on each face (where the limit surface is the face's plane, x, y or z =
// +-1), less the top's centre; and 69 targets over the middle of the top,
// raised into a Gaussian bump 0.25 high and 0.1 wide. Without the anchors
// the springs, far stiffer than the surface, would pull the coarse cube,
// which cannot form so narrow a bump, into a wild shape.
MatrixX3 bumpTargets(bool anchored = true) {
  std::vector<Vector3> points;
  for (int axis = 0; axis < 3 && anchored; ++axis) {
    for (double side : {-1.0, 1.0}) {
      for (double u : {-0.5, 0.0, 0.5}) {
        for (double w : {-0.5, 0.0, 0.5}) {
          if (axis == 2 && side > 0 && u == 0.0 && w == 0.0) continue;
          Vector3 p;
          p(axis) = side;
          p((axis + 1) % 3) = u;
          p((axis + 2) % 3) = w;
          points.push_back(p);
        }
      }
    }
  }
  for (int i = -4; i <= 4; ++i) {
    for (int j = -4; j <= 4; ++j) {
      const double x = 0.075 * i, y = 0.075 * j, r2 = x * x + y * y;
      if (r2 < 0.35 * 0.35) points.emplace_back(x, y, 1.0 + 0.25 * std::exp(-r2 / (2 * 0.1 * 0.1)));
    }
  }
  MatrixX3 targets(points.size(), 3);
  for (std::size_t i = 0; i < points.size(); ++i) targets.row(i) = points[i].transpose();
  return targets;
}

DeformationResult deformCube(double stiffness, int maxLevel, bool local, bool anchored = true) {
  const MatrixX3 targets = bumpTargets(anchored);
  DeformationOptions options;
  options.tolerancePercent = 0.5;
  options.localRefinement = local;
  options.simulation.maxLevel = maxLevel;
  return deformSurface(makeCube98(), targets, Eigen::VectorXd::Constant(targets.rows(), stiffness), {}, options);
}

TEST(Deformation, RefinesOnlyNearTheTargetsUntilTheToleranceIsMet) {
  const DeformationResult local = deformCube(1000.0, 3, true);
  const DeformationResult global = deformCube(1000.0, 3, false);
  // Both meet 0.5 % at the second refinement (0.31 % and 0.35 % measured;
  // the coarse cube is 2.7 % off, its first refinement 1.3 %), and stop
  // there rather than at the third level they were allowed.
  for (const DeformationResult* r : {&local, &global}) {
    EXPECT_TRUE(r->toleranceMet);
    EXPECT_LE(r->maxDistancePercent, 0.5);
    EXPECT_EQ(r->levels.back().level, 2);
    EXPECT_EQ(r->levelDistancesPercent.size(), r->levels.size());
    EXPECT_GT(r->levelDistancesPercent.front(), 1.0);
    // The anchors keep the cube (control points within 0.05 of +-1; 0.025
    // measured) and the bump rises above the top.
    const MatrixX3& p = r->mesh.points();
    for (int a = 0; a < 3; ++a) EXPECT_NEAR(p.col(a).minCoeff(), -1.0, 0.05);
    EXPECT_NEAR(p.col(0).maxCoeff(), 1.0, 0.05);
    EXPECT_NEAR(p.col(1).maxCoeff(), 1.0, 0.05);
    EXPECT_GT(p.col(2).maxCoeff(), 1.2);
  }
  EXPECT_TRUE(local.localRefinement);
  EXPECT_FALSE(global.localRefinement);
  // The same refined mesh (1538 control vertices), but only the bump's
  // faces' new points move: 187 free points measured against 1538; a
  // quarter leaves room for the ring rule and still fails if every point
  // were freed.
  EXPECT_EQ(local.mesh.vertexCount(), global.mesh.vertexCount());
  EXPECT_EQ(global.levels.back().freeControlPoints, global.mesh.vertexCount());
  EXPECT_LT(local.levels.back().freeControlPoints, global.levels.back().freeControlPoints / 4);
  // Nothing turned over at any level (0 measured).
  for (const DeformationResult* r : {&local, &global}) {
    ASSERT_EQ(r->levelTurnedOverPercent.size(), r->levels.size());
    for (double percent : r->levelTurnedOverPercent) EXPECT_EQ(percent, 0.0);
  }
}

TEST(Deformation, ReportsASurfaceTurnedOver) {
  // Without the anchors, springs of 1000 N/mm against tension 0.1 fold the
  // coarse cube through itself to meet a bump it cannot form (6.7 % of its
  // area turned over measured; the top's control points at z 3.9, the bottom
  // risen above z = 0.97). 1 % leaves room for the solver's rounding and
  // fails if the fold goes unseen. Springs of 10 N/mm only bow the top.
  const DeformationResult folded = deformCube(1000.0, 0, true, false);
  EXPECT_GT(folded.turnedOverPercent, 1.0);
  EXPECT_TRUE(folded.restarts.empty());  // no finer level allowed
  EXPECT_EQ(deformCube(10.0, 0, true, false).turnedOverPercent, 0.0);

  // The measure itself: a surface against itself turns nothing over; the
  // flat sheet mirrored in x turns all of it over (its normal, du x dv,
  // reverses when one coordinate does).
  const ControlMesh sheet = makeSheet81();
  const LimitSurface surface(sheet);
  MatrixX3 mirrored = sheet.points();
  mirrored.col(0) *= -1.0;
  EXPECT_EQ(turnedOverAreaPercent(surface, sheet.points(), surface, sheet.points()), 0.0);
  EXPECT_NEAR(turnedOverAreaPercent(surface, sheet.points(), surface, mirrored), 100.0, 1e-9);
}

TEST(Deformation, StartsAgainPastALevelThatTurnedOver) {
  // With finer levels allowed, the fold is not refined: the deformation
  // starts again from the cube refined once, which forms the bump (0.19 %
  // measured, 0.5 % asked) without turning over, its bottom kept (z -0.95
  // measured).
  const DeformationResult refined = deformCube(1000.0, 3, true, false);
  ASSERT_GE(refined.levels.size(), 2u);
  EXPECT_EQ(refined.restarts, std::vector<int>{1});
  EXPECT_GT(refined.levelTurnedOverPercent[0], 1.0);
  EXPECT_EQ(refined.turnedOverPercent, 0.0);
  EXPECT_TRUE(refined.toleranceMet);
  EXPECT_LT(refined.mesh.points().col(2).minCoeff(), -0.9);

  // The 8-vertex cube needs a refinement to isolate its corners, so its
  // levels 0 and 1 have the same elements: each restart still goes one level
  // past the level that turned over, and never past the last allowed.
  Eigen::Matrix<double, 8, 3> corners;
  corners << -1, -1, -1, 1, -1, -1, 1, 1, -1, -1, 1, -1, -1, -1, 1, 1, -1, 1, 1, 1, 1, -1, 1, 1;
  const ControlMesh cube8 = ControlMesh::fromPolygons(
      corners, {{0, 3, 2, 1}, {4, 5, 6, 7}, {0, 1, 5, 4}, {1, 2, 6, 5}, {2, 3, 7, 6}, {3, 0, 4, 7}});
  const MatrixX3 targets = bumpTargets(false);
  for (int maxLevel = 1; maxLevel <= 3; ++maxLevel) {
    DeformationOptions options;
    options.tolerancePercent = 0.5;
    options.simulation.maxLevel = maxLevel;
    const DeformationResult r =
        deformSurface(cube8, targets, Eigen::VectorXd::Constant(targets.rows(), 1000.0), {}, options);
    for (const int restart : r.restarts) {
      EXPECT_EQ(r.levels[restart].level, r.levels[restart - 1].level + 1) << maxLevel;
      EXPECT_GE(r.levelTurnedOverPercent[restart - 1], kRestartTurnedOverPercent) << maxLevel;
    }
    EXPECT_LE(r.levels.back().level, maxLevel);
    // Level 2 turns 16.7 % over (measured): with level 3 allowed, it starts
    // again there.
    if (maxLevel == 3) {
      EXPECT_GE(r.restarts.size(), 1u);
    }
  }
}

TEST(Deformation, EndsRefinementThatBringsTheTargetsNoCloser) {
  // Soft springs (10 N/mm) are balanced by the surface's elasticity about
  // 2.2 % from their targets from the second refinement on (4.2, 2.6, 2.2,
  // 2.2 % measured): the third refinement gains nothing, and the fourth is
  // not made.
  const DeformationResult r = deformCube(10.0, 4, true);
  EXPECT_FALSE(r.toleranceMet);
  EXPECT_EQ(r.levels.back().level, 3);
  ASSERT_EQ(r.levelDistancesPercent.size(), 4u);
  EXPECT_GT(r.levelDistancesPercent.back(), (1.0 - kLeastRefinementGain) * r.levelDistancesPercent[2]);
}

TEST(Deformation, ReportsAnUnmetToleranceWithoutRefinement) {
  const DeformationResult r = deformCube(1000.0, 0, true);
  EXPECT_FALSE(r.toleranceMet);
  EXPECT_EQ(r.levels.size(), 1u);
  EXPECT_GT(r.maxDistancePercent, 0.5);
  EXPECT_EQ(r.springLengths.size(), bumpTargets().rows());
}

TEST(Deformation, RefinesLocallyUnderTheStaticSchemeOnly) {
  DeformationOptions options;
  EXPECT_TRUE(options.refinesLocally());
  options.simulation.integrator.scheme = IntegrationScheme::FirstOrder;
  EXPECT_FALSE(options.refinesLocally());
}

TEST(Deformation, RefusesBadOptions) {
  const MatrixX3 targets = bumpTargets();
  const Eigen::VectorXd stiffness = Eigen::VectorXd::Constant(targets.rows(), 10.0);
  DeformationOptions options;
  options.tolerancePercent = 0.0;
  EXPECT_THROW(deformSurface(makeCube98(), targets, stiffness, {}, options), Error);
  options.tolerancePercent = std::nan("");
  EXPECT_THROW(deformSurface(makeCube98(), targets, stiffness, {}, options), Error);
  options.tolerancePercent = 1.0;
  EXPECT_THROW(deformSurface(makeCube98(), MatrixX3(0, 3), Eigen::VectorXd(0), {}, options), Error);
}

}  // namespace
}  // namespace dynsub
