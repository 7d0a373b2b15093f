// simulate() end to end, against answers known without it: a pure-spring
// problem's equilibrium is the direct least-squares solution for every
// scheme and solver; the static scheme's energy falls to the equilibrium, its
// fixed vertices stay. (The static scheme on shape recovery, its main user:
// ShapeRecoveryUnitTest.cpp.)
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <random>
#include <stdexcept>
#include <string>
#include <tuple>

#include <Eigen/SparseCholesky>
#include <unsupported/Eigen/KroneckerProduct>

#include "dynsub/ParallelFor.h"
#include "TestPointClouds.h"
#include "dynsub/ClosestPoint.h"
#include "dynsub/Error.h"
#include "dynsub/CatmullClark.h"
#include "dynsub/ForceModel.h"
#include "dynsub/InitialModels.h"
#include "dynsub/LimitSurface.h"
#include "dynsub/Simulation.h"
#include "dynsub/StandardMeshes.h"
#include "dynsub/Tessellation.h"

namespace dynsub {
namespace {

// Springs from targets near the cube's surface, attached once: at equilibrium
// K p = sum k J^T (d - J p), i.e. (K + J^T k J) p = J^T k d, solved directly.
class PureSpringTest : public ::testing::TestWithParam<std::tuple<IntegrationScheme, LinearSolver>> {};

TEST_P(PureSpringTest, EquilibriumIsTheDirectLeastSquaresSolution) {
  const ControlMesh cube = makeCube98();
  const LimitSurface surface(cube);
  std::mt19937_64 random(7);
  std::uniform_real_distribution<double> jitter(-0.2, 0.2);
  const TriangleSurface samples = tessellate(surface, cube.points(), 2);
  MatrixX3 targets = samples.points;
  for (Eigen::Index i = 0; i < targets.rows(); ++i) targets.row(i) += Vector3(jitter(random), jitter(random), jitter(random)).transpose() + 0.3 * samples.normals.row(i);
  const Eigen::VectorXd stiffness = Eigen::VectorXd::Constant(targets.rows(), 5.0);
  SpringForceModel springs(targets, stiffness, SpringForceModel::Attach::NearestAtLevelStart);

  SimulationOptions options;
  options.integrator.scheme = std::get<0>(GetParam());
  options.integrator.solver = std::get<1>(GetParam());
  options.integrator.timeStep = 0.5;
  options.equilibrium.energyTolerance = 1e-14;
  options.equilibrium.motionTolerance = 1e-11;
  options.equilibrium.maxSteps = 5000;
  const SimulationResult result = simulate(cube, {&springs}, {}, options);
  ASSERT_TRUE(result.levels.back().converged);

  // The attachments the springs used: nearest points to the initial surface.
  ClosestPointLocator locator(surface);
  locator.update(cube.points());
  std::vector<Spring> attached;
  for (const ClosestPoint& c : locator.findAll(targets)) attached.push_back(Spring{c.point, Vector3::Zero(), 5.0});
  for (size_t i = 0; i < attached.size(); ++i) attached[i].target = targets.row(i).transpose();
  const PhysicalMatrices m = assemblePhysicalMatrices(surface, options.material);
  const SymmetricMatrix lhs = m.stiffness + SymmetricMatrix(springStiffness(surface, attached));
  Eigen::SimplicialLDLT<SymmetricMatrix> direct(lhs);
  ASSERT_EQ(direct.info(), Eigen::Success);
  const MatrixX3 zeros = MatrixX3::Zero(cube.vertexCount(), 3);
  const MatrixX3 rhs = springForces(surface, zeros, attached);  // J^T k d
  const MatrixX3 expected = direct.solve(Eigen::MatrixXd(rhs));
  // The dynamics stop when steps move points by < 1e-11 of the size (~3.5);
  // the remaining distance to equilibrium is of that order.
  EXPECT_LT((result.mesh.points() - expected).cwiseAbs().maxCoeff(), 1e-7);
}

INSTANTIATE_TEST_SUITE_P(
    AllSchemesAndSolvers, PureSpringTest,
    ::testing::Combine(::testing::Values(IntegrationScheme::FirstOrder, IntegrationScheme::SecondOrder),
                       ::testing::Values(LinearSolver::Cholesky, LinearSolver::ConjugateGradient,
                                         LinearSolver::PreconditionedConjugateGradient)),
    [](const auto& info) {
      return std::string(std::get<0>(info.param) == IntegrationScheme::FirstOrder ? "FirstOrder" : "SecondOrder") +
             (std::get<1>(info.param) == LinearSolver::Cholesky ? "Cholesky"
              : std::get<1>(info.param) == LinearSolver::ConjugateGradient ? "CG" : "PCG");
    });
// The static scheme has its own solver (StaticSolver.h); springs held at
// their attachments make its Newton step exact.
INSTANTIATE_TEST_SUITE_P(StaticScheme, PureSpringTest,
                         ::testing::Values(std::make_tuple(IntegrationScheme::Static, LinearSolver::Cholesky)));

// Points on the limit surface of `mesh`, scaled 1.2-fold about the origin (the
// cube's centre): targets the surface moves out to.
MatrixX3 liftedTargets(const ControlMesh& mesh) {
  return tessellate(LimitSurface(mesh), mesh.points(), 1).points * 1.2;
}

// A fixed control vertex stays exactly where it was under the static scheme.
TEST(StaticScheme, FixedVerticesStay) {
  const ControlMesh cube = makeCube98();
  const MatrixX3 targets = liftedTargets(cube);
  SpringForceModel springs(targets, Eigen::VectorXd::Constant(targets.rows(), 1.0),
                           SpringForceModel::Attach::NearestEachStep);
  SimulationOptions options;
  options.integrator.scheme = IntegrationScheme::Static;
  const SimulationResult result = simulate(cube, {&springs}, {0, 17}, options);
  EXPECT_EQ(result.mesh.points().row(0), cube.points().row(0));
  EXPECT_EQ(result.mesh.points().row(17), cube.points().row(17));
  EXPECT_GT((result.mesh.points() - cube.points()).cwiseAbs().maxCoeff(), 0.05);
}

// Static steps, elasticity weakened 4-fold per level and per relaxation.
SimulationOptions relaxingOptions(int maxLevel, int relaxations) {
  SimulationOptions options;
  options.integrator.scheme = IntegrationScheme::Static;
  options.maxLevel = maxLevel;
  options.elasticityPerLevel = 0.25;
  options.relaxations = relaxations;
  return options;
}

// A level refused as close (FitVerdict::Relax) runs on at its own level with
// its elasticity weakened by the factor per level, while relaxations are
// left; refused outright (Refine), or with none left, it is refined.
TEST(StaticScheme, ALevelRefusedAsCloseRelaxesBeforeItIsRefined) {
  const ControlMesh cube = makeCube98();
  const MatrixX3 targets = liftedTargets(cube);
  for (const auto& [first, relaxations, secondVertices, secondElasticity] :
       {std::make_tuple(FitVerdict::Relax, 1, 98, 0.25), std::make_tuple(FitVerdict::Relax, 0, 386, 0.25),
        std::make_tuple(FitVerdict::Refine, 1, 386, 0.25)}) {
    SpringForceModel springs(targets, Eigen::VectorXd::Constant(targets.rows(), 1.0),
                             SpringForceModel::Attach::NearestEachStep);
    const SimulationOptions options = relaxingOptions(1, relaxations);
    int asked = 0;  // at levels' ends
    const AcceptFit accept = [&, first = first](const LimitSurface&, const MatrixX3&, FitAsk when) {
      if (when != FitAsk::LevelEnd) return FitVerdict::Settle;
      return ++asked == 1 ? first : FitVerdict::Settle;
    };
    const SimulationResult result = simulate(cube, {&springs}, {}, options, accept);
    ASSERT_EQ(result.levels.size(), 2u) << relaxations;
    EXPECT_EQ(result.levels[0].elasticity, 1.0);
    EXPECT_EQ(result.levels[1].controlVertices, secondVertices) << relaxations;
    EXPECT_EQ(result.levels[1].level, secondVertices == 98 ? 0 : 1);
    EXPECT_EQ(result.levels[1].elasticity, secondElasticity);
    EXPECT_EQ(result.mesh.vertexCount(), secondVertices);
  }
}

// Local refinement (RefineRegion): naming one face of the 98-vertex cube
// frees that face's 4 edge points and its face point beside the 98 carried
// points, and the level's Newton systems factor without a shift. On a cube
// of 8 vertices of valence 3 the subdivision matrix has a null vector
// (alternating signs), so a local step there would leave a direction that
// moves nothing: it is refined globally instead, every point free.
TEST(StaticScheme, LocalRefinementFreesTheNamedFacesPoints) {
  const ControlMesh cube98 = makeCube98();
  MatrixX3 corners(8, 3);
  corners << -1, -1, -1, 1, -1, -1, 1, 1, -1, -1, 1, -1, -1, -1, 1, 1, -1, 1, 1, 1, 1, -1, 1, 1;
  const ControlMesh cube8 = ControlMesh::fromPolygons(
      20.0 * corners, {{0, 3, 2, 1}, {4, 5, 6, 7}, {0, 1, 5, 4}, {1, 2, 6, 5}, {2, 3, 7, 6}, {3, 0, 4, 7}});
  for (const auto& [mesh, expectedFree] : {std::make_pair(cube98, 98 + 5), std::make_pair(cube8, 26)}) {
    const MatrixX3 targets = liftedTargets(mesh);
    SpringForceModel springs(targets, Eigen::VectorXd::Constant(targets.rows(), 1.0),
                             SpringForceModel::Attach::NearestEachStep);
    int asked = 0;
    const AcceptFit accept = [&](const LimitSurface&, const MatrixX3&, FitAsk when) {
      if (when != FitAsk::LevelEnd) return FitVerdict::Settle;
      return ++asked == 1 ? FitVerdict::Refine : FitVerdict::Settle;
    };
    const RefineRegion oneFace = [](const Topology&) { return std::vector<int>{0}; };
    const SimulationResult result = simulate(mesh, {&springs}, {}, relaxingOptions(1, 0), accept, nullptr, oneFace);
    ASSERT_EQ(result.levels.size(), 2u);
    EXPECT_EQ(result.levels[1].controlVertices, subdivide(mesh).mesh.vertexCount());
    EXPECT_EQ(result.levels[1].freeControlPoints, expectedFree) << mesh.vertexCount();
    EXPECT_EQ(result.levels[1].stabilizerUpdates, 0) << mesh.vertexCount();
    EXPECT_EQ(result.surface->controlVertexCount(), result.mesh.vertexCount());
  }
}

// The flat sheet's boundary held, its centre pulled up by springs, refined
// twice: every boundary point of the final mesh stays on the square's rim at
// z = 0 (the boundary's new vertex and edge points are determined by the held
// ones alone), globally, and locally with the pulled faces named, which frees
// fewer points. A vertex held alone inside the sheet cannot stay under a free
// basis (its vertex point blends free neighbours): a local step there is taken
// globally, and the vertex stays where the refinement put it.
TEST(StaticScheme, HeldPointsStayHeldThroughRefinement) {
  const ControlMesh sheet = makeSheet81();
  std::vector<int> boundary;
  for (int v = 0; v < sheet.vertexCount(); ++v) {
    if (sheet.topology().isBoundaryVertex(v)) boundary.push_back(v);
  }
  MatrixX3 targets(5, 3);
  targets << 0, 0, 0.9, 0.25, 0, 0.8, -0.25, 0, 0.8, 0, 0.25, 0.8, 0, -0.25, 0.8;
  const AcceptFit refineTwice = [](const LimitSurface&, const MatrixX3&, FitAsk when) {
    return when == FitAsk::LevelEnd ? FitVerdict::Refine : FitVerdict::Settle;
  };
  const int centreVertex = 40;  // (0, 0); vertices keep their numbers through refinement
  const int cornerVertex = 0;   // (-1, -1)
  // The faces at the centre and at a corner, and a ring around them: the
  // corner's reach the boundary, whose new points the held ones determine.
  const RefineRegion centre = [&](const Topology& mesh) {
    std::vector<int> faces = mesh.vertexFaces(centreVertex);
    for (int f : mesh.vertexFaces(cornerVertex)) faces.push_back(f);
    return grownFaces(mesh, faces, 1);
  };
  int freeGlobal = 0, freeLocal = 0;
  for (const bool local : {false, true}) {
    SpringForceModel springs(targets, Eigen::VectorXd::Constant(targets.rows(), 20.0),
                             SpringForceModel::Attach::NearestAtLevelStart);
    const SimulationResult result =
        simulate(sheet, {&springs}, boundary, relaxingOptions(2, 0), refineTwice, nullptr, local ? centre : nullptr);
    ASSERT_EQ(result.levels.size(), 3u);
    const MatrixX3& points = result.mesh.points();
    int rim = 0;
    for (int v = 0; v < result.mesh.vertexCount(); ++v) {
      if (!result.mesh.topology().isBoundaryVertex(v)) continue;
      ++rim;
      // Subdivision's weights on held points (sums of a few binary
      // fractions): exact up to rounding.
      EXPECT_NEAR(points(v, 2), 0.0, 1e-12) << v;
      EXPECT_NEAR(std::max(std::abs(points(v, 0)), std::abs(points(v, 1))), 1.0, 1e-12) << v;
    }
    EXPECT_EQ(rim, 128);
    EXPECT_GT(points.col(2).maxCoeff(), 0.5);  // the centre rose toward the springs (z 0.8-0.9)
    (local ? freeLocal : freeGlobal) = result.levels.back().freeControlPoints;
    EXPECT_FALSE(result.levels[0].localRefinement);
    for (int level = 1; level < 3; ++level) EXPECT_EQ(result.levels[level].localRefinement, local) << level;
  }
  EXPECT_EQ(freeGlobal, 1089 - 128);  // every point but the boundary's
  EXPECT_LT(freeLocal, freeGlobal / 2);

  const auto holdCentre = [&](int maxLevel) {
    SpringForceModel springs(targets, Eigen::VectorXd::Constant(targets.rows(), 20.0),
                             SpringForceModel::Attach::NearestAtLevelStart);
    return simulate(sheet, {&springs}, {centreVertex}, relaxingOptions(maxLevel, 0), refineTwice, nullptr, centre);
  };
  const SimulationResult held = holdCentre(1);
  ASSERT_EQ(held.levels.size(), 2u);
  EXPECT_EQ(held.levels[1].freeControlPoints, held.levels[1].controlVertices - 1);
  EXPECT_FALSE(held.levels[1].localRefinement);  // asked for, and refined globally instead
  // Where level 0's equilibrium (the same run stopped there) subdivides it
  // to; each level's equilibrium is one exact Newton step of linear springs,
  // so the two runs agree to rounding.
  const MatrixX3 start = subdivide(holdCentre(0).mesh).mesh.points();
  EXPECT_LT((held.mesh.points().row(centreVertex) - start.row(centreVertex)).norm(), 1e-9);
  EXPECT_GT(start(centreVertex, 2), 0.1);  // lifted by its neighbours, then held

  // The rule as a caller sees it: the held boundary's refinement is the
  // refined sheet's boundary (64 of 289 points), and a vertex held alone
  // inside holds only itself.
  const SubdividedMesh refined = subdivide(sheet);
  std::vector<int> refinedBoundary;
  for (int v = 0; v < refined.mesh.vertexCount(); ++v) {
    if (refined.mesh.topology().isBoundaryVertex(v)) refinedBoundary.push_back(v);
  }
  EXPECT_EQ(refinedBoundary.size(), 64u);
  EXPECT_EQ(refinedFixedVertices(refined.subdivisionMatrix, boundary), refinedBoundary);
  EXPECT_EQ(refinedFixedVertices(refined.subdivisionMatrix, {centreVertex}), std::vector<int>{centreVertex});
}

// With a rest shape (SimulationOptions::restShape) the elasticity holds the
// initial shape: springs already met move nothing, before refinement and
// after it, global or local (the rest shape is carried as the points are),
// after a relaxation (which weakens K), and under time steps (whose energy,
// rounding near the rest shape, is no divergence).
// The torus stretched along x and lifted on one side (Data/Deform's
// torus_pull) keeps its tube, where without a rest shape the tension
// flattens it to a ribbon.
TEST(StaticScheme, ARestShapeHoldsTheSurfaceWhereNothingPulls) {
  const ControlMesh torus = makeTorus32();
  const RefineRegion firstFace = [](const Topology&) { return std::vector<int>{0}; };
  const MatrixX3 met = tessellate(LimitSurface(torus), torus.points(), 1).points;
  const MatrixX3 refined = subdivide(torus).mesh.points();
  for (const IntegrationScheme scheme : {IntegrationScheme::Static, IntegrationScheme::FirstOrder}) {
    for (const bool local : {false, true}) {
      SimulationOptions options = relaxingOptions(1, 1);
      options.integrator.scheme = scheme;
      options.restShape = true;
      int asked = 0;  // relaxed once, then refined once
      const AcceptFit accept = [&](const LimitSurface&, const MatrixX3&, FitAsk when) {
        if (when != FitAsk::LevelEnd) return FitVerdict::Settle;
        ++asked;
        return asked == 1 ? FitVerdict::Relax : asked == 2 ? FitVerdict::Refine : FitVerdict::Settle;
      };
      SpringForceModel springs(met, Eigen::VectorXd::Constant(met.rows(), 1.0),
                               SpringForceModel::Attach::NearestAtLevelStart);
      const SimulationResult result =
          simulate(torus, {&springs}, {}, options, accept, nullptr, local ? firstFace : nullptr);
      ASSERT_EQ(result.levels.size(), 3u);
      EXPECT_LT((result.mesh.points() - refined).cwiseAbs().maxCoeff(), 1e-9) << local;
      for (const LevelSummary& level : result.levels) EXPECT_EQ(level.divergences, 0);
    }
  }

  MatrixX3 pull(4, 3);
  pull << 2.0, 0, 0, -2.0, 0, 0, 0, 1.2, 0.8, 0, -1.2, -0.8;
  Eigen::VectorXd stiffness(4);
  stiffness << 10, 10, 5, 5;
  // The tube's height where the ring is stretched (near y = 0, x < 0); 2/3
  // on the initial limit surface.
  const auto tubeHeight = [&](bool restShape) {
    SpringForceModel springs(pull, stiffness, SpringForceModel::Attach::NearestAtLevelStart);
    SimulationOptions o;
    o.integrator.scheme = IntegrationScheme::Static;
    o.restShape = restShape;
    const SimulationResult result = simulate(torus, {&springs}, {}, o);
    const MatrixX3 p = tessellate(*result.surface, result.mesh.points(), 8).points;
    double low = 0.0, high = 0.0;
    for (Eigen::Index i = 0; i < p.rows(); ++i) {
      if (std::abs(p(i, 1)) < 0.05 && p(i, 0) < 0.0) {
        low = std::min(low, p(i, 2));
        high = std::max(high, p(i, 2));
      }
    }
    return high - low;
  };
  EXPECT_GT(tubeHeight(true), 0.6);   // 0.71 measured
  EXPECT_LT(tubeHeight(false), 0.2);  // 0.06 measured
}

// A result whose level was relaxed says so in its origin, and a refit from it
// continues at the relaxed elasticity with only the relaxations left: with
// none left, a Relax verdict ends the refit at its one level, where a fresh
// fit from the same mesh would have run on with the elasticity weakened.
TEST(StaticScheme, ARefitContinuesAtItsOriginsRelaxedElasticity) {
  const ControlMesh cube = makeCube98();
  const MatrixX3 targets = liftedTargets(cube);
  SpringForceModel springs(targets, Eigen::VectorXd::Constant(targets.rows(), 1.0),
                           SpringForceModel::Attach::NearestEachStep);
  const SimulationOptions options = relaxingOptions(0, 1);
  int asked = 0;
  const AcceptFit relaxOnce = [&](const LimitSurface&, const MatrixX3&, FitAsk when) {
    if (when != FitAsk::LevelEnd) return FitVerdict::Settle;
    return ++asked == 1 ? FitVerdict::Relax : FitVerdict::Settle;
  };
  const SimulationResult first = simulate(cube, {&springs}, {}, options, relaxOnce);
  ASSERT_EQ(first.levels.size(), 2u);
  EXPECT_EQ(first.origin.level, 0);
  EXPECT_EQ(first.origin.relaxed, 1);

  const AcceptFit alwaysRelax = [](const LimitSurface&, const MatrixX3&, FitAsk when) {
    return when == FitAsk::LevelEnd ? FitVerdict::Relax : FitVerdict::Settle;
  };
  SimulationOptions refit = options;
  refit.origin = first.origin;
  const SimulationResult again = simulate(first.mesh, {&springs}, {}, refit, alwaysRelax);
  ASSERT_EQ(again.levels.size(), 1u);
  EXPECT_EQ(again.levels[0].elasticity, 0.25);
  EXPECT_EQ(again.origin.relaxed, 1);

  const SimulationResult fresh = simulate(first.mesh, {&springs}, {}, options, alwaysRelax);
  ASSERT_EQ(fresh.levels.size(), 2u);
  EXPECT_EQ(fresh.levels[0].elasticity, 1.0);
  EXPECT_EQ(fresh.levels[1].elasticity, 0.25);

  refit.origin.relaxed = -1;
  EXPECT_THROW(simulate(first.mesh, {&springs}, {}, refit, alwaysRelax), Error);
}

// The last level, with a relaxation left, is asked at the looser rule too
// (FitAsk::LastLevelLooseRule): Relax ends it there and runs it on with
// weaker elasticity; Refine, with no level left to refine into, lets it go
// on to the full rule.
TEST(StaticScheme, TheLastLevelRelaxesAtTheLooserRule) {
  const ControlMesh cube = makeCube98();
  const MatrixX3 targets = liftedTargets(cube);
  for (const FitVerdict answer : {FitVerdict::Relax, FitVerdict::Refine}) {
    SpringForceModel springs(targets, Eigen::VectorXd::Constant(targets.rows(), 1.0),
                             SpringForceModel::Attach::NearestEachStep);
    SimulationOptions options = relaxingOptions(0, 1);
    options.equilibrium.coarseLevelFactor = 30.0;
    int looseAsks = 0, lastLooseAsks = 0;
    const AcceptFit accept = [&](const LimitSurface&, const MatrixX3&, FitAsk when) {
      if (when == FitAsk::LooseRule) ++looseAsks;
      if (when != FitAsk::LastLevelLooseRule) return FitVerdict::Settle;
      ++lastLooseAsks;
      return answer;
    };
    const SimulationResult result = simulate(cube, {&springs}, {}, options, accept);
    const bool relaxed = answer == FitVerdict::Relax;
    EXPECT_EQ(looseAsks, 0);
    EXPECT_EQ(lastLooseAsks, 1);  // the relaxed run has no relaxation left
    ASSERT_EQ(result.levels.size(), relaxed ? 2u : 1u);
    EXPECT_EQ(result.levels[0].coarse, relaxed);
    EXPECT_FALSE(result.levels.back().coarse);
    EXPECT_EQ(result.levels.back().elasticity, relaxed ? 0.25 : 1.0);
    EXPECT_EQ(result.levels.back().level, 0);
  }
}

// Springs from each control point to a target, stabilized exactly (their
// stiffness k I is the integrator's S): the steps are stable at any time step,
// but a large one moves the points farther than the model's size when the
// targets lie farther than that, which counts as a divergence (Simulation.h).
// With `jumpAfter` > 0, the targets move as far again after that many
// evaluations of a level.
class PullToTargets final : public ForceModel {
 public:
  PullToTargets(MatrixX3 targets, double stiffness, int jumpAfter = 0)
      : targets_(std::move(targets)), k_(stiffness), jumpAfter_(jumpAfter) {}
  void beginLevel(const LimitSurface&, const SurfaceQuadrature&, const MatrixX3&) override {
    // A level restarted this often is a simulation that no longer ends.
    if (++levels_ > 50) throw std::runtime_error("the level was restarted over 50 times");
    evaluations_ = 0;
  }
  MatrixX3 generalizedForce(const MatrixX3& controlPoints, double&) override {
    const bool jumped = jumpAfter_ > 0 && ++evaluations_ > jumpAfter_;
    return k_ * ((jumped ? MatrixX3(targets_.rowwise() + kJump) : targets_) - controlPoints);
  }
  inline static const Eigen::RowVector3d kJump{10.0, 0.0, 0.0};
  SparseMatrix stabilizingStiffness(const MatrixX3& controlPoints) override {
    SparseMatrix s(controlPoints.rows(), controlPoints.rows());
    s.setIdentity();
    return k_ * s;
  }

 private:
  MatrixX3 targets_;
  double k_;
  int jumpAfter_, evaluations_ = 0, levels_ = 0;
};

// A level that diverged in its first steps grows its halved time step back
// to the one asked for once the energy falls, and reaches the same
// equilibrium in fewer steps.
TEST(TimeSteps, AHalvedStepGrowsBackOnceTheEnergyFalls) {
  const ControlMesh cube = makeCube98();
  // Targets 3 model sizes away: the first steps at 4 s jump there at once.
  const MatrixX3 targets = cube.points().rowwise() + PullToTargets::kJump;
  auto run = [&](int regrowth, int jumpAfter = 0) {
    PullToTargets pull(targets, 1.0, jumpAfter);
    SimulationOptions options;
    options.integrator.timeStep = 4.0;
    options.equilibrium.maxSteps = 5000;
    options.timeStepRegrowth = regrowth;
    // The two halvings these runs need (4 -> 2 -> 1 s) and no more: a restart
    // at a regrown step must not count as one.
    options.maxTimeStepHalvings = 2;
    return simulate(cube, {&pull}, {}, options);
  };
  const SimulationResult halved = run(0), regrown = run(30);
  ASSERT_TRUE(halved.levels.back().converged);
  ASSERT_TRUE(regrown.levels.back().converged);
  EXPECT_LT(halved.levels.back().timeStep, 4.0);   // the first steps diverged at 4 s
  EXPECT_EQ(regrown.levels.back().timeStep, 4.0);  // and the step grew back
  // report.json's record of it: the level's restarts, at 4 and at 2 s.
  EXPECT_EQ(halved.levels.back().divergences, 2);
  EXPECT_EQ(regrown.levels.back().divergences, 2);
  EXPECT_LT(regrown.steps, halved.steps);
  // The same equilibrium K p = f_p. Each run stops once steps move the
  // surface by under 1e-4 of the model's size (3.5 mm), so each may stop some
  // 1e-3 mm short of it; measured 0.001 mm apart.
  EXPECT_LT((regrown.mesh.points() - halved.mesh.points()).cwiseAbs().maxCoeff(), 0.01);

  // When the targets jump again after the step has grown back, the level
  // diverges at the regrown step: it restarts at the step it started with and
  // grows no more to a step that diverged, so it ends as it does without
  // regrowth (not with the halvings used up).
  const SimulationResult jumpHalved = run(0, 60), jumpRegrown = run(30, 60);
  ASSERT_TRUE(jumpHalved.levels.back().converged);
  ASSERT_TRUE(jumpRegrown.levels.back().converged);
  EXPECT_EQ(jumpRegrown.levels.back().timeStep, jumpHalved.levels.back().timeStep);
  // One restart more than without regrowth: the divergence at the regrown step.
  EXPECT_EQ(jumpRegrown.levels.back().divergences, jumpHalved.levels.back().divergences + 1);
  EXPECT_EQ(jumpRegrown.steps, jumpHalved.steps);
  EXPECT_EQ(jumpRegrown.mesh.points(), jumpHalved.mesh.points());
}

// parallelFor's workers run the forces' and searches' per-item work; an
// exception from any item must come back to the caller (a thread's uncaught
// exception ends the process), after every chunk has ended, and it must be
// the same one whatever the timing: the first chunk's. Both chunks throw
// here; on one core the items run in order, and item 10 throws first too.
TEST(ParallelFor, RethrowsTheFirstChunksExceptionOnceEveryChunkHasEnded) {
  std::atomic<int> done{0};
  const auto body = [&](Eigen::Index i) {
    if (i == 10 || i == 900) throw std::runtime_error("item " + std::to_string(i));
    ++done;
  };
  try {
    parallelFor(1000, 2, body);
    FAIL() << "no exception came back";
  } catch (const std::runtime_error& e) {
    EXPECT_STREQ(e.what(), "item 10");
  }
  // Each chunk stopped at its own throw: the first after items 0-9, the
  // second (if there was one) after 500-899; nothing ran after the rethrow.
  const int expected = hardwareThreads() >= 2 ? 10 + 400 : 10;
  EXPECT_EQ(done.load(), expected);
}

}  // namespace
}  // namespace dynsub
