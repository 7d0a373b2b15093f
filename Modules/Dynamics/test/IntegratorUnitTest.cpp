// Time integration (Integrator.h): the linear solvers take the same step; a
// singular system is refused.
#include <gtest/gtest.h>

#include "dynsub/Error.h"
#include "dynsub/Integrator.h"
#include "dynsub/LimitSurface.h"
#include "dynsub/PhysicalMatrices.h"
#include "dynsub/StandardMeshes.h"

namespace dynsub {
namespace {

TEST(Integrator, SolversTakeTheSameStep) {
  const ControlMesh cube = makeCube98();
  const LimitSurface surface(cube);
  const PhysicalMatrices m = assemblePhysicalMatrices(surface, Material{});
  const Matrix3X p = cube.points();
  const Matrix3X previous = 0.99 * p;
  const Matrix3X force = 0.1 * p;
  for (IntegrationScheme scheme : {IntegrationScheme::FirstOrder, IntegrationScheme::SecondOrder}) {
    IntegratorOptions options;
    options.scheme = scheme;
    options.solver = LinearSolver::Cholesky;
    const Matrix3X reference = Integrator(m, SymmetricMatrix(), {0, 5}, options).step(previous, p, force);
    EXPECT_EQ(reference.row(0), p.row(0));  // fixed vertices stay
    EXPECT_EQ(reference.row(5), p.row(5));
    for (LinearSolver solver : {LinearSolver::ConjugateGradient, LinearSolver::PreconditionedConjugateGradient}) {
      options.solver = solver;
      Integrator integrator(m, SymmetricMatrix(), {0, 5}, options);
      // Relative residual 1e-10 on a system of condition ~1e3.
      EXPECT_LT((integrator.step(previous, p, force) - reference).cwiseAbs().maxCoeff(), 1e-7);
      EXPECT_GT(integrator.lastIterations(), 0);
    }
  }
}

TEST(Integrator, RefusesASingularSystem) {
  const LimitSurface surface(makeCube98());
  Material material;
  material.damping = 0.0;
  const PhysicalMatrices m = assemblePhysicalMatrices(surface, material);
  IntegratorOptions options;  // first order: D + 2 dt K, singular for translations when D = 0
  EXPECT_THROW(Integrator(m, SymmetricMatrix(), {}, options), Error);
}

}  // namespace
}  // namespace dynsub
