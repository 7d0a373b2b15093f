// Time integration (Integrator.h): a factored step satisfies eq. 31 / 32 with
// the force stiffness moved to the left; the linear solvers take the same
// step; a restabilized integrator takes a new one's step; a motion the limit
// surface does not show is held still; a singular system is refused.
#include <cmath>

#include <gtest/gtest.h>

#include "dynsub/CatmullClark.h"
#include "dynsub/Error.h"
#include "dynsub/Integrator.h"
#include "dynsub/LimitSurface.h"
#include "dynsub/PhysicalMatrices.h"
#include "dynsub/StandardMeshes.h"

namespace dynsub {
namespace {

// The factored step against the scheme's equation, row by row, from 98 to
// 6146 control vertices (where both fill-reducing orderings are tried). Some
// vertices are fixed and a force stiffness S is moved to the left.
class FactoredStep : public testing::TestWithParam<int> {};

TEST_P(FactoredStep, SolvesTheSchemesEquation) {
  const int levels = GetParam();
  ControlMesh mesh = makeCube98();
  for (int level = 0; level < levels; ++level) mesh = subdivide(mesh).mesh;
  const LimitSurface surface(mesh);
  AssemblyOptions assembly;
  assembly.elementSize = std::ldexp(1.0, -levels);
  const PhysicalMatrices m = assemblePhysicalMatrices(surface, Material{}, assembly);
  const SymmetricMatrix stabilizing = 0.3 * m.mass;  // any symmetric S on the elements' pattern
  const MatrixX3 p = mesh.points();
  const MatrixX3 previous = 0.99 * p + MatrixX3::Constant(p.rows(), 3, 0.001);
  const MatrixX3 force = (MatrixX3::Random(p.rows(), 3) * 0.1).eval();
  const std::vector<int> fixed = {3, 17, 400};
  for (IntegrationScheme scheme : {IntegrationScheme::FirstOrder, IntegrationScheme::SecondOrder}) {
    IntegratorOptions options;
    options.scheme = scheme;
    options.timeStep = 0.3;
    const double dt = options.timeStep;
    const MatrixX3 next = Integrator(m, stabilizing, fixed, options).step(previous, p, force);
    const SymmetricMatrix k = m.stiffness + stabilizing;
    MatrixX3 lhs, rhs;
    if (scheme == IntegrationScheme::FirstOrder) {
      lhs = m.damping * next + 2.0 * dt * (k * next);
      rhs = 2.0 * dt * (force + stabilizing * p) + m.damping * previous;
    } else {
      lhs = 2.0 * (m.mass * next) + dt * (m.damping * next) + 2.0 * dt * dt * (k * next);
      rhs = 2.0 * dt * dt * (force + stabilizing * p) + dt * (m.damping * previous) - 2.0 * (m.mass * previous) +
            4.0 * (m.mass * p);
    }
    for (int v : fixed) {
      EXPECT_EQ(next.row(v), p.row(v));
      lhs.row(v).setZero();  // a fixed vertex's row is not an equation
      rhs.row(v).setZero();
    }
    // A backward-stable solve leaves a residual of a few hundred rounding
    // errors of the terms' size (thousands of unknowns, about 50 per row); 1e-11 of
    // the right-hand side's largest entry is ten to a hundred times that.
    EXPECT_LT((lhs - rhs).cwiseAbs().maxCoeff(), 1e-11 * rhs.cwiseAbs().maxCoeff()) << toString(scheme);
  }
}

INSTANTIATE_TEST_SUITE_P(Integrator, FactoredStep, testing::Values(2, 3),
                         [](const testing::TestParamInfo<int>& info) {
                           return std::to_string(info.param == 2 ? 1538 : 6146) + "ControlVertices";
                         });

// The cube's matrices and one state of it, for the steps compared below.
struct CubeStep {
  PhysicalMatrices m;
  MatrixX3 p, previous, force;
};
CubeStep cubeStep() {
  const ControlMesh cube = makeCube98();
  CubeStep c;
  c.m = assemblePhysicalMatrices(LimitSurface(cube), Material{});
  c.p = cube.points();
  c.previous = 0.99 * c.p;
  c.force = 0.1 * c.p;
  return c;
}

TEST(Integrator, SolversTakeTheSameStep) {
  const auto [m, p, previous, force] = cubeStep();
  for (IntegrationScheme scheme : {IntegrationScheme::FirstOrder, IntegrationScheme::SecondOrder}) {
    IntegratorOptions options;
    options.scheme = scheme;
    options.solver = LinearSolver::Cholesky;
    const MatrixX3 reference = Integrator(m, SymmetricMatrix(), {0, 5}, options).step(previous, p, force);
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

TEST(Integrator, RestabilizedTakesTheStepOfANewIntegrator) {
  // The restabilized integrator keeps the first one's ordering and symbolic
  // analysis; a new one with the second stiffness analyzes the same pattern
  // afresh. Same ordering, same numeric factorization: equal to the bit. A
  // stiffness outside the elements' pattern changes the pattern, and then
  // the analysis is redone (equal to rounding: its ordering may differ).
  const auto [m, p, previous, force] = cubeStep();
  const std::vector<int> fixed = {2, 7};
  const int n = static_cast<int>(p.rows());
  SymmetricMatrix outside(n, n);  // couples two vertices no element shares
  outside.insert(0, n - 1) = 0.5;
  outside.insert(n - 1, 0) = 0.5;
  outside.insert(0, 0) = 1.0;
  outside.insert(n - 1, n - 1) = 1.0;
  for (IntegrationScheme scheme : {IntegrationScheme::FirstOrder, IntegrationScheme::SecondOrder}) {
    IntegratorOptions options;
    options.scheme = scheme;
    Integrator integrator(m, SymmetricMatrix(0.3 * m.mass), fixed, options);
    const MatrixX3 first = integrator.step(previous, p, force);
    integrator.restabilize(m, SymmetricMatrix(2.5 * m.mass));
    const MatrixX3 second = integrator.step(previous, p, force);
    EXPECT_EQ(second, Integrator(m, SymmetricMatrix(2.5 * m.mass), fixed, options).step(previous, p, force));
    EXPECT_GT((second - first).cwiseAbs().maxCoeff(), 1e-6);  // the new stiffness took effect
    EXPECT_EQ(second.row(2), p.row(2));
    integrator.restabilize(m, outside);
    EXPECT_LT((integrator.step(previous, p, force) - Integrator(m, outside, fixed, options).step(previous, p, force))
                  .cwiseAbs()
                  .maxCoeff(),
              1e-12 * p.cwiseAbs().maxCoeff());
  }
}

TEST(Integrator, HoldsStillAMotionTheLimitSurfaceDoesNotShow) {
  // The 8-vertex cube's vertices moved by +d and -d alternately leave its
  // limit surface where it is, so M and D are singular. Shifted alike, they
  // make that motion a free mass with damping: the first-order step holds
  // its amount at p(t-dt)'s, the second-order one moves it by eq. 31 with
  // K = 0, and the rest moves as K asks.
  MatrixX3 corners(8, 3);
  corners << -1, -1, -1, 1, -1, -1, 1, 1, -1, -1, 1, -1, -1, -1, 1, 1, -1, 1, 1, 1, 1, -1, 1, 1;
  const ControlMesh cube8 = ControlMesh::fromPolygons(
      20.0 * corners, {{0, 3, 2, 1}, {4, 5, 6, 7}, {0, 1, 5, 4}, {1, 2, 6, 5}, {2, 3, 7, 6}, {3, 0, 4, 7}});
  const PhysicalMatrices m = assemblePhysicalMatrices(LimitSurface(cube8), Material{});
  Eigen::VectorXd alternating(8);
  for (int v = 0; v < 8; ++v) alternating(v) = corners(v, 0) * corners(v, 1) * corners(v, 2);
  alternating.normalize();
  EXPECT_LT((m.damping * alternating).norm(), 1e-9 * m.damping.diagonal().norm());  // singular indeed
  const MatrixX3 p = cube8.points();
  MatrixX3 previous = p;
  previous.col(2) += 0.5 * alternating;  // 0.5 mm of the hidden motion along z
  for (IntegrationScheme scheme : {IntegrationScheme::FirstOrder, IntegrationScheme::SecondOrder}) {
    IntegratorOptions options;
    options.scheme = scheme;
    const MatrixX3 next = Integrator(m, SymmetricMatrix(), {}, options).step(previous, p, MatrixX3::Zero(8, 3));
    ASSERT_TRUE(next.allFinite());
    EXPECT_GT((next - p).cwiseAbs().maxCoeff(), 1e-3);  // the tension shrinks the cube
    // To 1e-4 mm: the shift is 1e-9 of the diagonal, so rounding reaches
    // the hidden amount about 1e9-fold (1e-6-1e-5 mm measured here).
    const double dt = options.timeStep;
    for (int a = 0; a < 3; ++a) {
      const double before = alternating.dot(previous.col(a)), now = alternating.dot(p.col(a));
      const double expected =
          scheme == IntegrationScheme::FirstOrder ? before : (4.0 * now + (dt - 2.0) * before) / (2.0 + dt);
      EXPECT_NEAR(alternating.dot(next.col(a)), expected, 1e-4) << a;
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
