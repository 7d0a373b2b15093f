// simulate() end to end, against answers known without it: a pure-spring
// problem's equilibrium is the direct least-squares solution for every
// scheme and solver; the static scheme's energy falls to the equilibrium, its
// fixed vertices stay. (The static scheme on shape recovery, its main user:
// ShapeRecoveryUnitTest.cpp.)
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <random>
#include <stdexcept>
#include <string>

#include <Eigen/SparseCholesky>
#include <unsupported/Eigen/KroneckerProduct>

#include "dynsub/ParallelFor.h"
#include "TestPointClouds.h"
#include "dynsub/ClosestPoint.h"
#include "dynsub/Error.h"
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
  Matrix3X targets = samples.points;
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
  const Matrix3X zeros = Matrix3X::Zero(cube.vertexCount(), 3);
  const Matrix3X rhs = springForces(surface, zeros, attached);  // J^T k d
  const Matrix3X expected = direct.solve(Eigen::MatrixXd(rhs));
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

// A fixed control vertex stays exactly where it was under the static scheme.
TEST(StaticScheme, FixedVerticesStay) {
  const ControlMesh cube = makeCube98();
  const LimitSurface surface(cube);
  Matrix3X targets = tessellate(surface, cube.points(), 1).points * 1.2;
  SpringForceModel springs(targets, Eigen::VectorXd::Constant(targets.rows(), 1.0),
                           SpringForceModel::Attach::NearestEachStep);
  SimulationOptions options;
  options.integrator.scheme = IntegrationScheme::Static;
  const SimulationResult result = simulate(cube, {&springs}, {0, 17}, options);
  EXPECT_EQ(result.mesh.points().row(0), cube.points().row(0));
  EXPECT_EQ(result.mesh.points().row(17), cube.points().row(17));
  EXPECT_GT((result.mesh.points() - cube.points()).cwiseAbs().maxCoeff(), 0.05);
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
