// The dynamics end to end, against answers known without it: a pure-spring
// problem's equilibrium is the direct least-squares solution; solvers agree;
// refinement keeps the surface; smallest enclosing spheres against brute force;
// analytic point clouds (sphere, 3:2:1 ellipsoid, torus) are recovered to the
// papers' 1 % tolerance; runs are repeatable; bad input is refused.
#include <gtest/gtest.h>

#include <algorithm>
#include <random>

#include <Eigen/SparseCholesky>
#include <unsupported/Eigen/KroneckerProduct>

#include "dynsub/CatmullClark.h"
#include "dynsub/ClosestPoint.h"
#include "dynsub/EnclosingSphere.h"
#include "dynsub/Error.h"
#include "dynsub/ForceModel.h"
#include "dynsub/Integrator.h"
#include "dynsub/LimitSurface.h"
#include "dynsub/ShapeRecovery.h"
#include "dynsub/Simulation.h"
#include "dynsub/StaticSolver.h"
#include "dynsub/StandardMeshes.h"
#include "dynsub/Tessellation.h"

namespace dynsub {
namespace {

Vector3 randomDirection(std::mt19937_64& random) {
  std::normal_distribution<double> normal;
  Vector3 v;
  do {
    v = Vector3(normal(random), normal(random), normal(random));
  } while (v.norm() < 1e-6);
  return v.normalized();
}

Matrix3X ellipsoidPoints(int n, const Vector3& axes, unsigned seed) {
  std::mt19937_64 random(seed);
  Matrix3X points(n, 3);
  for (int i = 0; i < n; ++i) points.row(i) = randomDirection(random).cwiseProduct(axes).transpose();
  return points;
}

Matrix3X torusPoints(int n, double ring, double tube, unsigned seed) {
  std::mt19937_64 random(seed);
  std::uniform_real_distribution<double> angle(0.0, 2.0 * M_PI);
  Matrix3X points(n, 3);
  for (int i = 0; i < n; ++i) {
    const double theta = angle(random), phi = angle(random);
    const double r = ring + tube * std::cos(phi);
    points.row(i) << r * std::cos(theta), r * std::sin(theta), tube * std::sin(phi);
  }
  return points;
}

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

// The 3N x 3N Newton matrix against its definition, built densely:
// K (x) I_3 + sum_q (J_q^T J_q) (x) B_q, unknown 3 v + a. 400 points: from
// 256 on, the points' sums are shared between threads (on a machine with more
// than one core), which must give the definition, and the same bits from one
// build to the next. (That a serial build gives those bits too follows from
// each element's sums being made by one thread; this test cannot choose the
// thread count.)
TEST(TangentStiffness, MatchesItsDenseDefinition) {
  const ControlMesh mesh = makeCube98();
  const LimitSurface surface(mesh);
  const PhysicalMatrices m = assemblePhysicalMatrices(surface, Material{});
  TangentStiffness h(surface), again(surface);
  h.reset(m.stiffness);
  again.reset(SymmetricMatrix(2.0 * m.stiffness));
  again.resetToLast();
  again.reset(m.stiffness);
  const int n = surface.controlVertexCount();
  Eigen::MatrixXd expected = Eigen::kroneckerProduct(Eigen::MatrixXd(m.stiffness), Eigen::Matrix3d::Identity());
  std::mt19937_64 random(3);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  for (int i = 0; i < 400; ++i) {
    const ElementPoint q{static_cast<int>(unit(random) * surface.elementCount()) % surface.elementCount(), unit(random),
                         unit(random)};
    Eigen::Matrix3d b = Eigen::Matrix3d::Random();
    b = (b * b.transpose()).eval();
    h.addPoint(q, b);
    again.addPoint(q, b);
    const Eigen::VectorXd j = Eigen::RowVectorXd(surface.limitOperator({q}).row(0)).transpose();
    expected += Eigen::kroneckerProduct(Eigen::MatrixXd(j * j.transpose()), b);
  }
  const SparseMatrix scalar = springStiffness(surface, {Spring{ElementPoint{5, 0.3, 0.6}, Vector3::Zero(), 2.0}});
  h.addScalar(scalar);
  again.addScalar(scalar);
  expected += Eigen::kroneckerProduct(Eigen::MatrixXd(scalar), Eigen::Matrix3d::Identity());
  const Eigen::MatrixXd actual(h.matrix());
  ASSERT_EQ(actual.rows(), 3 * n);
  // The lower triangle alone is stored.
  expected = Eigen::MatrixXd(expected.triangularView<Eigen::Lower>());
  // Sums of the same products in another order: rounding of ~1e-15 of the entries.
  EXPECT_LT((actual - expected).cwiseAbs().maxCoeff(), 1e-12 * expected.cwiseAbs().maxCoeff());
  EXPECT_EQ(Eigen::MatrixXd(again.matrix()), actual);

  // A new step from K alone (the Newton steps of a level): the points are gone.
  h.resetToLast();
  const Eigen::MatrixXd k = Eigen::kroneckerProduct(Eigen::MatrixXd(m.stiffness), Eigen::Matrix3d::Identity());
  EXPECT_EQ(Eigen::MatrixXd(h.matrix()), Eigen::MatrixXd(k.triangularView<Eigen::Lower>()));
}

// With springs to the nearest points the static scheme's total energy (the
// function whose minimum is the papers' equilibrium) falls at every step.
// Its equilibrium rule watches the shape, not the control points (Simulation.h:
// the parametrization's slide along the surface is left out), so the shape it
// stops at must be the equilibrium's: the same fit run on to a rule 10 000
// times tighter ends on the same surface and the same fit error.
TEST(StaticScheme, EnergyFallsAtEveryStepToTheEquilibrium) {
  const Matrix3X points = ellipsoidPoints(1500, Vector3(30, 20, 10), 11);
  FitOptions options;
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

// Levels that are refined end at the looser rule of coarseLevelFactor; the
// last level, and a level whose fit is accepted, end by the full rule. The
// ellipsoid fits to 1 % at its first level, so a fit to 1 % must not change
// at all; asked for 0.01 % (beyond reach), it is refined once, and the first
// level then ends sooner.
TEST(StaticScheme, OnlyRefinedLevelsEndAtTheLooserRule) {
  const Matrix3X points = ellipsoidPoints(1500, Vector3(30, 20, 10), 11);
  const ControlMesh initial = initialModel(points, InitialShape::Sphere);
  FitOptions full;
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

// A dead zone of z mm: a spring whose target lies within z of the surface
// pulls not at all; one at distance L beyond pulls as a plain spring to a
// target L - z away along the same line. Targets are put on the limit
// normals a little off the surface (0.01-0.05 of the cube's size of about
// 2, well inside its curvature radius), so each spring attaches where its
// target was lifted from, in both models.
TEST(SpringForceModel, ADeadZonePullsOnlyBeyondIt) {
  const ControlMesh cube = makeCube98();
  const LimitSurface surface(cube);
  const Matrix3X onSurface = tessellate(surface, cube.points(), 1).points;
  ClosestPointLocator locator(surface);
  locator.update(cube.points());
  Matrix3X normals(onSurface.rows(), 3);
  const std::vector<ClosestPoint> nearest = locator.findAll(onSurface);
  for (Eigen::Index i = 0; i < onSurface.rows(); ++i) normals.row(i) = nearest[i].normal.transpose();
  const double zone = 0.02;
  const SurfaceQuadrature quadrature = makeSurfaceQuadrature(surface);
  const Eigen::VectorXd k = Eigen::VectorXd::Constant(onSurface.rows(), 3.0);
  auto forceOf = [&](const Matrix3X& targets, double deadZone, double& potential) {
    SpringForceModel springs(targets, k, SpringForceModel::Attach::NearestEachStep);
    springs.setDeadZone(deadZone);
    springs.beginLevel(surface, quadrature, cube.points());
    potential = 0.0;
    return springs.generalizedForce(cube.points(), potential);
  };
  double potential = 0.0;
  const Matrix3X inside = forceOf(onSurface + 0.01 * normals, zone, potential);
  EXPECT_EQ(inside.cwiseAbs().maxCoeff(), 0.0);
  EXPECT_EQ(potential, 0.0);
  double beyondPotential = 0.0, plainPotential = 0.0;
  const Matrix3X beyond = forceOf(onSurface + 0.05 * normals, zone, beyondPotential);
  const Matrix3X plain = forceOf(onSurface + 0.03 * normals, 0.0, plainPotential);
  // The attachments agree to the closest-point search's tolerance (1e-9 of the size).
  EXPECT_LT((beyond - plain).cwiseAbs().maxCoeff(), 1e-7 * plain.cwiseAbs().maxCoeff());
  EXPECT_NEAR(beyondPotential, plainPotential, 1e-7 * plainPotential);
  EXPECT_GT(plain.cwiseAbs().maxCoeff(), 0.0);
  SpringForceModel springs(onSurface, k, SpringForceModel::Attach::NearestEachStep);
  EXPECT_THROW(springs.setDeadZone(-1.0), Error);
  EXPECT_THROW(springs.setDeadZone(std::nan("")), Error);
}

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

// A radial well like an image force across an edge: k times the unit
// direction towards the sphere of radius R, falling linearly to zero over the
// last `width` mm. Its slope is k / width.
class RadialWell final : public ForceField {
 public:
  RadialWell(double radius, double strength, double width) : radius_(radius), strength_(strength), width_(width) {}
  Matrix3X forcesAt(const Matrix3X& points) const override {
    Matrix3X forces(points.rows(), 3);
    for (Eigen::Index i = 0; i < points.rows(); ++i) {
      const double r = points.row(i).norm();
      const double towards = std::clamp((radius_ - r) / width_, -1.0, 1.0);
      forces.row(i) = strength_ * towards * points.row(i) / r;
    }
    return forces;
  }
  double slopeBound() const override { return strength_ / width_; }

 private:
  double radius_, strength_, width_;
};

TEST(FieldForces, StiffnessIntegratesTheSlopeOverTheArea) {
  // A rigid translation u of the whole surface: u^T S u = slope * area * |u|^2.
  const ControlMesh cube = makeCube98();
  const LimitSurface surface(cube);
  const SurfaceQuadrature quadrature = makeSurfaceQuadrature(surface, 4);
  const SparseMatrix stiffness = fieldStiffness(quadrature, cube.points(), 3.0);
  const Matrix3X su = quadrature.Ju * cube.points(), sv = quadrature.Jv * cube.points();
  double area = 0.0;
  for (Eigen::Index i = 0; i < su.rows(); ++i) area += quadrature.weights(i) * su.row(i).cross(sv.row(i)).norm();
  const Eigen::VectorXd ones = Eigen::VectorXd::Ones(cube.vertexCount());
  EXPECT_NEAR(ones.dot(stiffness * ones), 3.0 * area, 1e-9 * area);
}

TEST(FieldForces, AReversingFieldSettlesOnItsEdge) {
  // The well is 0.2 mm wide and 20 times stronger than the surface's tension
  // at that radius: explicit, its force would swing the surface across the
  // edge every step. Stabilized by its slope bound, the level must reach
  // equilibrium, with the surface on the edge to within the well's width plus
  // the small inward pull of tension (k r / tension ~ 0.1 mm).
  ControlMesh cube = makeCube98();
  cube.setPoints(cube.points() * 3.0);  // limit surface radius about 2 mm
  const RadialWell well(4.0, 1.0, 0.2);
  FieldForceModel field(well);
  SimulationOptions options;
  options.material.tensionU = options.material.tensionV = 0.05;
  options.material.rigidityUU = options.material.rigidityVV = options.material.rigidityUV = 0.0;
  const SimulationResult result = simulate(cube, {&field}, {}, options);
  ASSERT_EQ(result.levels.size(), 1u);
  EXPECT_TRUE(result.levels[0].converged);
  const LimitSurface surface(result.mesh);
  const Matrix3X points = tessellate(surface, result.mesh.points(), 4).points;
  const Eigen::VectorXd radii = points.rowwise().norm();
  EXPECT_GT(radii.minCoeff(), 4.0 - 0.35);
  EXPECT_LT(radii.maxCoeff(), 4.0 + 0.2);
}

TEST(Refinement, LeavesTheLimitSurfaceUnchanged) {
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

TEST(EnclosingSphere, MatchesBruteForce) {
  std::mt19937_64 random(11);
  std::uniform_real_distribution<double> coordinate(-1.0, 1.0);
  for (int trial = 0; trial < 5; ++trial) {
    const int n = 14;
    Matrix3X points(n, 3);
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
          Matrix3X three(3, 3);
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
  const Matrix3X points = ellipsoidPoints(5000, Vector3(3.0, 3.0, 3.0), 3);
  const Sphere s = smallestEnclosingSphere(points);
  EXPECT_NEAR(s.radius, 3.0, 1e-3);  // 5000 random points leave no cap wider than ~0.05 rad uncovered
  EXPECT_LT(s.center.norm(), 2e-3);
}

TEST(PointCloudChecks, RefuseDegenerateData) {
  EXPECT_THROW(checkPointCloud(Matrix3X::Random(3, 3), "three.xyz"), Error);
  Matrix3X nan = Matrix3X::Random(10, 3);
  nan(4, 1) = std::nan("");
  EXPECT_THROW(checkPointCloud(nan, "nan.xyz"), Error);
  EXPECT_THROW(checkPointCloud(Matrix3X::Ones(10, 3), "same.xyz"), Error);
  Matrix3X flat = Matrix3X::Random(10, 3);
  flat.col(2).setConstant(4.0);
  try {
    checkPointCloud(flat, "flat.xyz");
    FAIL() << "coplanar points were accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("flat.xyz: all points lie on a plane"), std::string::npos) << e.what();
  }
  Matrix3X line(10, 3);
  for (int i = 0; i < 10; ++i) line.row(i) << i, 2 * i, -i;
  EXPECT_THROW(checkPointCloud(line, "line.xyz"), Error);
  EXPECT_NO_THROW(checkPointCloud(Matrix3X::Random(10, 3), "fine.xyz"));
}

TEST(ShapeRecovery, RefusesAnOpenInitialModel) {
  const Matrix3X points = ellipsoidPoints(200, Vector3(2, 2, 2), 5);
  EXPECT_THROW(fitPointCloud(points, makeSheet81(), FitOptions{}), Error);
}

struct RecoveryCase {
  std::string name;
  Matrix3X points;
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

TEST(ShapeRecovery, SameInputGivesIdenticalOutput) {
  const Matrix3X points = torusPoints(800, 30, 10, 9);
  const ControlMesh initial = initialModel(points, InitialShape::Torus);
  const FitResult a = fitPointCloud(points, initial, FitOptions{});
  const FitResult b = fitPointCloud(points, initial, FitOptions{});
  EXPECT_EQ(a.steps, b.steps);
  EXPECT_TRUE((a.mesh.points().array() == b.mesh.points().array()).all());
  EXPECT_EQ(a.error.maxPercent, b.error.maxPercent);
}

}  // namespace
}  // namespace dynsub
