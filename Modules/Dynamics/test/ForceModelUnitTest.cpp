// Force models (ForceModel.h): a spring's dead zone and a sample of
// springs; a field's stabilizing stiffness and its settling on an edge; a
// pressure field evaluated with a force field.
#include <gtest/gtest.h>

#include <algorithm>

#include <cmath>

#include "dynsub/ClosestPoint.h"
#include "dynsub/Error.h"
#include "dynsub/ForceModel.h"
#include "dynsub/Forces.h"
#include "dynsub/LimitSurface.h"
#include "dynsub/Simulation.h"
#include "dynsub/StandardMeshes.h"
#include "dynsub/Tessellation.h"

namespace dynsub {
namespace {

// The unit limit normals at points of the surface.
MatrixX3 normalsAt(const LimitSurface& surface, const MatrixX3& controlPoints, const MatrixX3& onSurface) {
  ClosestPointLocator locator(surface);
  locator.update(controlPoints);
  const std::vector<ClosestPoint> nearest = locator.findAll(onSurface);
  MatrixX3 normals(onSurface.rows(), 3);
  for (Eigen::Index i = 0; i < onSurface.rows(); ++i) normals.row(i) = nearest[i].normal.transpose();
  return normals;
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
  const MatrixX3 onSurface = tessellate(surface, cube.points(), 1).points;
  const MatrixX3 normals = normalsAt(surface, cube.points(), onSurface);
  const double zone = 0.02;
  const SurfaceQuadrature quadrature = makeSurfaceQuadrature(surface);
  const Eigen::VectorXd k = Eigen::VectorXd::Constant(onSurface.rows(), 3.0);
  auto forceOf = [&](const MatrixX3& targets, double deadZone, double& potential) {
    SpringForceModel springs(targets, k, SpringForceModel::Attach::NearestEachStep);
    springs.setDeadZone(deadZone);
    springs.beginLevel(surface, quadrature, cube.points());
    potential = 0.0;
    return springs.generalizedForce(cube.points(), potential);
  };
  double potential = 0.0;
  const MatrixX3 inside = forceOf(onSurface + 0.01 * normals, zone, potential);
  EXPECT_EQ(inside.cwiseAbs().maxCoeff(), 0.0);
  EXPECT_EQ(potential, 0.0);
  double beyondPotential = 0.0, plainPotential = 0.0;
  const MatrixX3 beyond = forceOf(onSurface + 0.05 * normals, zone, beyondPotential);
  const MatrixX3 plain = forceOf(onSurface + 0.03 * normals, 0.0, plainPotential);
  // The attachments agree to the closest-point search's tolerance (1e-9 of the size).
  EXPECT_LT((beyond - plain).cwiseAbs().maxCoeff(), 1e-7 * plain.cwiseAbs().maxCoeff());
  EXPECT_NEAR(beyondPotential, plainPotential, 1e-7 * plainPotential);
  EXPECT_GT(plain.cwiseAbs().maxCoeff(), 0.0);
  SpringForceModel springs(onSurface, k, SpringForceModel::Attach::NearestEachStep);
  EXPECT_THROW(springs.setDeadZone(-1.0), Error);
  EXPECT_THROW(springs.setDeadZone(std::nan("")), Error);
}

// A sample of the springs (setSamplePerElement) pulls with the whole set's
// total stiffness: targets all lifted the same 0.03 off the surface give
// the whole set's potential, from perElement x E springs. With perElement
// x E at least the targets, or 0, every spring pulls.
TEST(SpringForceModel, ASampleHasTheWholeSetsStiffness) {
  const ControlMesh cube = makeCube98();
  const LimitSurface surface(cube);
  const MatrixX3 onSurface = tessellate(surface, cube.points(), 4).points;
  const MatrixX3 targets = onSurface + 0.03 * normalsAt(surface, cube.points(), onSurface);
  const SurfaceQuadrature quadrature = makeSurfaceQuadrature(surface);
  const Eigen::VectorXd k = Eigen::VectorXd::Constant(targets.rows(), 3.0);
  const double elements = surface.elementCount();
  ASSERT_GT(targets.rows(), 4 * elements);
  auto potentialOf = [&](double perElement, Eigen::Index& pulling) {
    SpringForceModel springs(targets, k, SpringForceModel::Attach::NearestEachStep);
    springs.setSamplePerElement(perElement);
    springs.beginLevel(surface, quadrature, cube.points());
    double potential = 0.0;
    springs.generalizedForce(cube.points(), potential);
    pulling = springs.lengths().size();
    return potential;
  };
  Eigen::Index all = 0, sample = 0, enough = 0;
  const double whole = potentialOf(0.0, all);
  EXPECT_EQ(all, targets.rows());
  // The attachments agree to the closest-point search's tolerance (1e-9 of the size).
  EXPECT_NEAR(potentialOf(2.0, sample), whole, 1e-7 * whole);
  EXPECT_EQ(sample, static_cast<Eigen::Index>(2.0 * elements));
  EXPECT_NEAR(potentialOf(static_cast<double>(targets.rows()) / elements, enough), whole, 1e-7 * whole);
  EXPECT_EQ(enough, targets.rows());
  // Fewer than one spring's worth still pulls with one.
  Eigen::Index one = 0;
  EXPECT_GT(potentialOf(0.1 / elements, one), 0.0);
  EXPECT_EQ(one, 1);
  SpringForceModel springs(targets, k, SpringForceModel::Attach::NearestEachStep);
  EXPECT_THROW(springs.setSamplePerElement(-1.0), Error);
  EXPECT_THROW(springs.setSamplePerElement(std::nan("")), Error);
}

// A radial well like an image force across an edge: k times the unit
// direction towards the sphere of radius R, falling linearly to zero over the
// last `width` mm. Its slope is k / width.
class RadialWell final : public ForceField {
 public:
  RadialWell(double radius, double strength, double width) : radius_(radius), strength_(strength), width_(width) {}
  MatrixX3 forcesAt(const MatrixX3& points) const override {
    MatrixX3 forces(points.rows(), 3);
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
  const MatrixX3 su = quadrature.Ju * cube.points(), sv = quadrature.Jv * cube.points();
  double area = 0.0;
  for (Eigen::Index i = 0; i < su.rows(); ++i) area += quadrature.weights(i) * su.row(i).cross(sv.row(i)).norm();
  const Eigen::VectorXd ones = Eigen::VectorXd::Ones(cube.vertexCount());
  EXPECT_NEAR(ones.dot(stiffness * ones), 3.0 * area, 1e-9 * area);
}

TEST(FieldForces, StiffnessEqualsTheProductOverTheQuadrature) {
  // The element-by-element sums against slope J^T W J formed by Eigen, on a
  // cube whose eight extraordinary vertices give special elements. The sums
  // run in another order, so they agree to rounding: 1e-13 of the largest
  // entry.
  const ControlMesh cube = makeCube98();
  const LimitSurface surface(cube);
  const SurfaceQuadrature quadrature = makeSurfaceQuadrature(surface, 3);
  const MatrixX3 points = cube.points() * 1.7;
  const SparseMatrix stiffness = fieldStiffness(quadrature, points, 0.6);
  const MatrixX3 su = quadrature.Ju * points, sv = quadrature.Jv * points;
  Eigen::VectorXd weights(su.rows());
  for (Eigen::Index i = 0; i < su.rows(); ++i) weights(i) = 0.6 * quadrature.weights(i) * su.row(i).cross(sv.row(i)).norm();
  const Eigen::MatrixXd expected = Eigen::MatrixXd(SparseMatrix(quadrature.J.transpose() * weights.asDiagonal() * quadrature.J));
  const Eigen::MatrixXd got = Eigen::MatrixXd(stiffness);
  EXPECT_LT((got - expected).cwiseAbs().maxCoeff(), 1e-13 * expected.cwiseAbs().maxCoeff());
  EXPECT_EQ(got, got.transpose());
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
  const MatrixX3 points = tessellate(surface, result.mesh.points(), 4).points;
  const Eigen::VectorXd radii = points.rowwise().norm();
  EXPECT_GT(radii.minCoeff(), 4.0 - 0.35);
  EXPECT_LT(radii.maxCoeff(), 4.0 + 0.2);
}

// A pressure that depends on where the surface is: +p above the plane z = 0,
// -p below. Its slope bound is what FieldForceModel adds to the field's.
class HalfSpacePressure final : public PressureField {
 public:
  explicit HalfSpacePressure(double pressure) : pressure_(pressure) {}
  Eigen::VectorXd pressuresAt(const MatrixX3& points) const override {
    return points.col(2).unaryExpr([this](double z) { return z > 0 ? pressure_ : -pressure_; });
  }
  double slopeBound() const override { return 2.0; }

 private:
  double pressure_;
};

TEST(FieldForces, APressureFieldActsWithTheForceFieldInOnePass) {
  // The field's forces plus the pressure's equal the two computed apart:
  // the field alone, and pressureForces at the quadrature points' own
  // pressures. A pressure of zero everywhere changes nothing.
  const ControlMesh cube = makeCube98();
  const LimitSurface surface(cube);
  const SurfaceQuadrature quadrature = makeSurfaceQuadrature(surface);
  const RadialWell well(0.8, 0.3, 0.2);
  const HalfSpacePressure halves(0.05);
  const MatrixX3 positions = quadrature.J * cube.points();
  const MatrixX3 apart = fieldForces(quadrature, cube.points(), well) +
                         pressureForces(quadrature, cube.points(), halves.pressuresAt(positions));
  const MatrixX3 together = fieldForces(quadrature, cube.points(), well, &halves);
  EXPECT_LT((together - apart).cwiseAbs().maxCoeff(), 1e-12 * apart.cwiseAbs().maxCoeff());
  EXPECT_GT((together - fieldForces(quadrature, cube.points(), well)).cwiseAbs().maxCoeff(), 0.0);
  const HalfSpacePressure uniform(0.0);
  EXPECT_EQ(fieldForces(quadrature, cube.points(), well, &uniform), fieldForces(quadrature, cube.points(), well));
  // The stabilizer takes both slopes: 0.3 / 0.2 for the well, 2 for the pressure.
  FieldForceModel alone(well), both(well, &halves);
  alone.beginLevel(surface, quadrature, cube.points());
  both.beginLevel(surface, quadrature, cube.points());
  const SparseMatrix expected = fieldStiffness(quadrature, cube.points(), 1.5 + 2.0);
  EXPECT_LT((both.stabilizingStiffness(cube.points()) - expected).norm(), 1e-12 * expected.norm());
  EXPECT_LT((alone.stabilizingStiffness(cube.points()) - fieldStiffness(quadrature, cube.points(), 1.5)).norm(),
            1e-12 * expected.norm());
}

}  // namespace
}  // namespace dynsub
