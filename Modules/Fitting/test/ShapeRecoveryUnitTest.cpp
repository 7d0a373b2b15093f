// Shape recovery (ShapeRecovery.h): analytic point clouds (sphere, 3:2:1
// ellipsoid, torus) recovered to the papers' 1 % tolerance; a noisy scan
// with outliers recovered to it by the bias rule; a fit ends where the
// tolerance is met; runs are
// repeatable; degenerate data and open initial models are refused; the
// static scheme's energy falls at every step and its refined levels end at
// the looser rule; local refinement frees points only where the data ask.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>

#include <gtest/gtest.h>

#include "TestPointClouds.h"
#include "dynsub/ClosestPoint.h"
#include "dynsub/Error.h"
#include "dynsub/LimitSurface.h"
#include "dynsub/Simulation.h"
#include "dynsub/ScanNoise.h"
#include "dynsub/ShapeRecovery.h"
#include "dynsub/StandardMeshes.h"
#include "dynsub/Tessellation.h"

namespace dynsub {
namespace {

TEST(PointCloudChecks, RefuseDegenerateData) {
  EXPECT_THROW(checkPointCloud(MatrixX3::Random(3, 3), "three.xyz"), Error);
  MatrixX3 nan = MatrixX3::Random(10, 3);
  nan(4, 1) = std::nan("");
  EXPECT_THROW(checkPointCloud(nan, "nan.xyz"), Error);
  EXPECT_THROW(checkPointCloud(MatrixX3::Ones(10, 3), "same.xyz"), Error);
  MatrixX3 flat = MatrixX3::Random(10, 3);
  flat.col(2).setConstant(4.0);
  try {
    checkPointCloud(flat, "flat.xyz");
    FAIL() << "coplanar points were accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("flat.xyz: all points lie on a plane"), std::string::npos) << e.what();
  }
  // A line whose points were written to 6 significant digits is still a line.
  MatrixX3 line(500, 3);
  for (int i = 0; i < 500; ++i)
    for (int a = 0; a < 3; ++a) {
      char written[32];
      std::snprintf(written, sizeof written, "%g", 0.0200401 * i * (a + 1));
      line(i, a) = std::stod(written);
    }
  try {
    checkPointCloud(line, "line.xyz");
    FAIL() << "collinear points were accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("line.xyz: all points lie on a line"), std::string::npos) << e.what();
  }
  EXPECT_NO_THROW(checkPointCloud(MatrixX3::Random(10, 3), "fine.xyz"));
}

TEST(ShapeRecovery, RefusesAnOpenInitialModel) {
  const MatrixX3 points = ellipsoidPoints(200, Vector3(2, 2, 2), 5);
  EXPECT_THROW(fitPointCloud(points, makeSheet81(), FitOptions{}), Error);
}

struct RecoveryCase {
  std::string name;
  MatrixX3 points;
  InitialShape init;
  int maxControlVertices;
};

class ShapeRecoveryTest : public ::testing::TestWithParam<int> {};

RecoveryCase recoveryCase(int index) {
  switch (index) {
    case 0: return {"sphere", ellipsoidPoints(1000, Vector3(40, 40, 40), 1), InitialShape::Sphere, 386};
    case 1: return {"ellipsoid321", ellipsoidPoints(1500, Vector3(60, 40, 20), 2), InitialShape::Sphere, 386};
    default: return {"torus", torusPoints(1500, 40, 15, 3), InitialShape::Torus, 2048};
  }
}

// The ICCV tolerance: max distance from a data point to the limit surface
// <= 1 % of the diameter of the smallest enclosing sphere.
TEST_P(ShapeRecoveryTest, RecoversAnalyticShapesToOnePercent) {
  const RecoveryCase c = recoveryCase(GetParam());
  const ControlMesh initial = initialModel(c.points, c.init);
  const FitResult result = fitPointCloud(c.points, initial, FitOptions{});
  EXPECT_LE(result.error.maxPercent, 1.0) << c.name;
  EXPECT_LE(result.mesh.vertexCount(), c.maxControlVertices) << c.name;
  EXPECT_LT(result.mesh.vertexCount(), c.points.rows()) << c.name;
  EXPECT_TRUE(result.mesh.points().allFinite());
}

INSTANTIATE_TEST_SUITE_P(Analytic, ShapeRecoveryTest, ::testing::Values(0, 1, 2),
                         [](const auto& info) { return recoveryCase(info.param).name; });

// A scan with 0.5 % noise (of the sphere's diameter, per coordinate) and 3 %
// outliers 4-12 mm off its surface: with the outliers set aside and the
// noise measured (ScanNoise.h), the bias rule stops the fit at its first
// level, where the max error rule would refine to the last, and the surface
// is within the 1 % tolerance of the noise-free sphere everywhere.
TEST(ShapeRecovery, NoisyScanStopsAtItsNoiseAndOutliersDoNotDragIt) {
  const double radius = 40.0, sigma = 0.4;
  MatrixX3 surface = ellipsoidPoints(1500, Vector3(radius, radius, radius), 21);
  std::mt19937_64 random(22);
  std::normal_distribution<double> normal(0.0, sigma);
  for (Eigen::Index i = 0; i < surface.rows(); ++i) {
    for (int a = 0; a < 3; ++a) surface(i, a) += normal(random);
  }
  // Outliers 4-12 mm off either side of the surface, as a scanner's spikes.
  std::uniform_real_distribution<double> offset(4.0, 12.0);
  MatrixX3 scan(surface.rows() + 45, 3);
  scan.topRows(surface.rows()) = surface;
  for (Eigen::Index i = surface.rows(); i < scan.rows(); ++i) {
    const double off = (i % 2 == 0 ? 1.0 : -1.0) * offset(random);
    scan.row(i) = (radius + off) * randomDirection(random).transpose();
  }
  const ScanNoise noise = estimateScanNoise(scan);
  EXPECT_NEAR(noise.sigma, sigma, 0.1 * sigma);
  const MatrixX3 data = withoutRows(scan, noise.outliers);
  FitOptions options;
  options.noise = noise.sigma;
  EXPECT_GE(scan.rows() - data.rows(), 43);  // 10 sigma and more off: nearly all found
  const FitResult result = fitPointCloud(data, initialModel(data, InitialShape::Sphere), options);
  EXPECT_TRUE(result.noiseLimited);
  EXPECT_TRUE(result.toleranceMet);
  EXPECT_EQ(result.levels.size(), 1u);
  EXPECT_GT(result.error.maxPercent, 1.0);  // the noise's reach
  EXPECT_LE(result.error.biasPercent, 1.0);
  const MatrixX3 truth = ellipsoidPoints(4000, Vector3(radius, radius, radius), 23);
  EXPECT_LE(measureFitError(*result.surface, result.mesh.points(), truth, 2.0 * radius).maxPercent, 1.0);

  // The same scan as clean data: every point, the papers' rule alone.
  FitOptions clean;
  clean.simulation.maxLevel = 1;
  const FitResult chased = fitPointCloud(scan, initialModel(scan, InitialShape::Sphere), clean);
  EXPECT_FALSE(chased.noiseLimited);
  EXPECT_EQ(chased.levels.size(), 2u);  // refined, and still above the tolerance
  EXPECT_FALSE(chased.toleranceMet);
}

TEST(ShapeRecovery, SameInputGivesIdenticalOutput) {
  const MatrixX3 points = torusPoints(800, 30, 10, 9);
  const ControlMesh initial = initialModel(points, InitialShape::Torus);
  const FitResult a = fitPointCloud(points, initial, FitOptions{});
  const FitResult b = fitPointCloud(points, initial, FitOptions{});
  EXPECT_EQ(a.steps, b.steps);
  EXPECT_TRUE((a.mesh.points().array() == b.mesh.points().array()).all());
  EXPECT_EQ(a.error.maxPercent, b.error.maxPercent);
}

// The static scheme (Simulation.h) on shape recovery.
// With springs to the nearest points the static scheme's total energy (the
// function whose minimum is the papers' equilibrium) falls at every step.
// Its equilibrium rule watches the shape, not the control points (Simulation.h:
// the parametrization's slide along the surface is left out), so the shape it
// stops at must be the equilibrium's: the same fit run on to a rule 10 000
// times tighter ends on the same surface and the same fit error.
TEST(StaticScheme, EnergyFallsAtEveryStepToTheEquilibrium) {
  const MatrixX3 points = ellipsoidPoints(1500, Vector3(30, 20, 10), 11);
  FitOptions options;
  options.toEquilibrium = true;
  ASSERT_EQ(options.simulation.integrator.scheme, IntegrationScheme::Static);
  std::vector<std::pair<int, double>> energies;
  const FitResult result = fitPointCloud(points, initialModel(points, InitialShape::Sphere), options,
                                         [&](const Progress& p) { energies.emplace_back(p.level, p.energy); });
  ASSERT_GT(energies.size(), 2u);
  for (size_t i = 1; i < energies.size(); ++i) {
    if (energies[i].first != energies[i - 1].first) continue;  // a new level starts from a refined mesh
    // The line search's own allowance for the energy sum's rounding.
    EXPECT_LE(energies[i].second, energies[i - 1].second + 1e-12 * std::abs(energies[i - 1].second)) << i;
  }
  for (const LevelSummary& level : result.levels) EXPECT_TRUE(level.converged);
  EXPECT_LE(result.error.maxPercent, 1.0);

  FitOptions tight = options;
  tight.simulation.equilibrium.energyTolerance = 1e-8;
  tight.simulation.equilibrium.motionTolerance = 1e-8;
  tight.simulation.equilibrium.maxSteps = 400;
  const FitResult reference = fitPointCloud(points, initialModel(points, InitialShape::Sphere), tight);
  ASSERT_EQ(reference.levels.size(), result.levels.size());
  EXPECT_GT(reference.steps, result.steps);
  const LimitSurface surface(result.mesh), referenceSurface(reference.mesh);
  ClosestPointLocator locator(referenceSurface);
  locator.update(reference.mesh.points());
  double apart = 0.0;
  for (const ClosestPoint& c : locator.findAll(tessellate(surface, result.mesh.points(), 4).points)) {
    apart = std::max(apart, c.distance);
  }
  // The rule's bound on a still step's motion is 1e-4 of the model's size
  // (about 7e-3 mm here); the two ends may differ by a few such steps.
  EXPECT_LT(apart, 2e-2);
  // Run on, the scheme reaches the papers' K p = f_p: the tangential force
  // imbalance the shape rule leaves is gone (measured 1e-3 relative).
  for (const LevelSummary& level : reference.levels) EXPECT_LT(level.residual, 2e-2);
  EXPECT_NEAR(result.error.maxPercent, reference.error.maxPercent, 1e-2);
}

// A fit ends at the first step where every data point is within the
// tolerance, in the static scheme and in time steps; the error it reports is
// that state's, measured by a full search. Run on to the equilibrium (the
// papers' rule), the same fit takes more steps and ends closer than was
// asked.
TEST(ShapeRecovery, EndsWhereTheToleranceIsMet) {
  const std::vector<std::pair<MatrixX3, IntegrationScheme>> cases = {
      {ellipsoidPoints(1500, Vector3(30, 20, 10), 11), IntegrationScheme::Static},
      {ellipsoidPoints(1000, Vector3(40, 40, 40), 1), IntegrationScheme::FirstOrder}};
  for (const auto& [points, scheme] : cases) {
    const ControlMesh initial = initialModel(points, InitialShape::Sphere);
    FitOptions options;
    options.simulation.integrator.scheme = scheme;
    options.simulation.integrator.timeStep = 0.5;
    const FitResult result = fitPointCloud(points, initial, options);
    ASSERT_EQ(result.levels.size(), 1u);
    EXPECT_EQ(result.levelErrors.size(), 1u);
    EXPECT_TRUE(result.levels.back().met) << static_cast<int>(scheme);
    EXPECT_TRUE(result.toleranceMet);
    EXPECT_LE(result.error.maxPercent, 1.0);
    const double diameter = 2.0 * result.enclosingSphere.radius;
    EXPECT_EQ(measureFitError(*result.surface, result.mesh.points(), points, diameter).maxPercent,
              result.error.maxPercent);

    FitOptions equilibrium = options;
    equilibrium.toEquilibrium = true;
    const FitResult toEquilibrium = fitPointCloud(points, initial, equilibrium);
    EXPECT_FALSE(toEquilibrium.levels.back().met);
    EXPECT_LT(result.steps, toEquilibrium.steps) << static_cast<int>(scheme);
    EXPECT_LT(toEquilibrium.error.maxPercent, result.error.maxPercent) << static_cast<int>(scheme);
  }
}

// Levels that are refined end at the looser rule of coarseLevelFactor; the
// last level, and a level whose fit is accepted, end by the full rule. The
// ellipsoid fits to 1 % at its first level, so a fit to 1 % must not change
// at all; asked for 0.01 % (beyond reach), it is refined once, and the first
// level then ends sooner.
TEST(StaticScheme, OnlyRefinedLevelsEndAtTheLooserRule) {
  const MatrixX3 points = ellipsoidPoints(1500, Vector3(30, 20, 10), 11);
  const ControlMesh initial = initialModel(points, InitialShape::Sphere);
  FitOptions full;
  full.toEquilibrium = true;
  full.simulation.equilibrium.coarseLevelFactor = 1.0;
  FitOptions coarse = full;
  coarse.simulation.equilibrium.coarseLevelFactor = 30.0;
  EXPECT_EQ(FitOptions().simulation.equilibrium.coarseLevelFactor, 30.0);  // fit's default

  const FitResult accepted = fitPointCloud(points, initial, full);
  const FitResult acceptedCoarse = fitPointCloud(points, initial, coarse);
  ASSERT_EQ(accepted.levels.size(), 1u);
  ASSERT_EQ(acceptedCoarse.levels.size(), 1u);
  EXPECT_EQ(acceptedCoarse.levelErrors.size(), 1u);  // asked twice, one level's error
  EXPECT_EQ(acceptedCoarse.steps, accepted.steps);
  EXPECT_EQ(acceptedCoarse.mesh.points(), accepted.mesh.points());  // the same steps, to the bit

  full.tolerancePercent = coarse.tolerancePercent = 0.01;
  full.simulation.maxLevel = coarse.simulation.maxLevel = 1;
  const FitResult refined = fitPointCloud(points, initial, full);
  const FitResult refinedCoarse = fitPointCloud(points, initial, coarse);
  ASSERT_EQ(refined.levels.size(), 2u);
  ASSERT_EQ(refinedCoarse.levels.size(), 2u);
  EXPECT_EQ(refinedCoarse.levelErrors.size(), 2u);
  EXPECT_LT(refinedCoarse.levels[0].steps, refined.levels[0].steps);
  for (const LevelSummary& level : refinedCoarse.levels) EXPECT_TRUE(level.converged);
  // The last level ends by the full rule from another start: the same fit to
  // a tenth of its error (both about 0.1 % of the diameter).
  EXPECT_NEAR(refinedCoarse.error.maxPercent, refined.error.maxPercent, 0.1 * refined.error.maxPercent);
}

// A sphere with one narrow bump, fitted to 0.5 %: only the faces near the
// bump need the next level. Local refinement must meet the tolerance at the
// same level as global refinement, with the refined mesh's limit surface
// (what the outputs write) the fitted one, and free under half its points:
// the bump covers about 1.5 % of the sphere's area, so even with the faces
// around it grown by kRefineRings most of the refined mesh stays the
// coarser level's (a cloud of this shape freed 150 of 386).
TEST(ShapeRecovery, LocalRefinementFreesPointsWhereTheDataAsk) {
  std::mt19937_64 random(5);
  MatrixX3 points(4000, 3);
  const Vector3 top(0, 0, 1);
  for (Eigen::Index i = 0; i < points.rows(); ++i) {
    const Vector3 d = randomDirection(random);
    const double angle = std::acos(std::clamp(d.dot(top), -1.0, 1.0));
    const double bump = 6.0 * std::exp(-angle * angle / (2.0 * 0.12 * 0.12));  // mm, about 5 mm wide
    points.row(i) = ((40.0 + bump) * d).transpose();
  }
  const ControlMesh initial = initialModel(points, InitialShape::Sphere);
  FitOptions global;
  global.tolerancePercent = 0.5;
  global.localRefinement = false;
  FitOptions local;
  ASSERT_TRUE(local.localRefinement);  // the default
  local.tolerancePercent = 0.5;
  const FitResult everywhere = fitPointCloud(points, initial, global);
  const FitResult where = fitPointCloud(points, initial, local);
  ASSERT_TRUE(everywhere.toleranceMet);
  ASSERT_TRUE(where.toleranceMet);
  ASSERT_GE(everywhere.levels.back().level, 1);
  EXPECT_EQ(where.levels.back().level, everywhere.levels.back().level);
  EXPECT_EQ(where.mesh.vertexCount(), everywhere.mesh.vertexCount());
  EXPECT_EQ(everywhere.levels.back().freeControlPoints, everywhere.mesh.vertexCount());
  EXPECT_LT(where.levels.back().freeControlPoints, everywhere.mesh.vertexCount() / 2);
  const double diameter = 2.0 * where.enclosingSphere.radius;
  EXPECT_EQ(where.surface->controlVertexCount(), where.mesh.vertexCount());
  EXPECT_NEAR(measureFitError(*where.surface, where.mesh.points(), points, diameter).maxPercent, where.error.maxPercent,
              1e-9);
}

}  // namespace
}  // namespace dynsub
