// The papers' initial models placed in space (InitialModels.h).
#include "dynsub/InitialModels.h"

#include <gtest/gtest.h>

#include <cmath>

#include "dynsub/Error.h"
#include "dynsub/LimitSurface.h"
#include "dynsub/Tessellation.h"

namespace dynsub {
namespace {

MatrixX3 limitPoints(const ControlMesh& mesh) {
  return tessellate(LimitSurface(mesh), mesh.points(), 8).points;
}

// The cube's limit surface reaches each semi-axis along its axis and no
// further: the largest coordinate along each axis, measured on the control
// vertices' limit positions, is the semi-axis (to rounding, 1e-12 mm); the
// 8 x 8 tessellation lies within it.
TEST(InitialModels, TheCubeSpansTheEllipsoidsSemiAxes) {
  const Vector3 centre(3, -4, 5), semiAxes(20, 12, 7);
  const Matrix3 axes = Eigen::AngleAxisd(0.7, Vector3(1, -2, 0.5).normalized()).toRotationMatrix();
  const ControlMesh cube = cubeInEllipsoid(centre, axes, semiAxes);
  const LimitSurface surface(cube);
  const MatrixX3 vertices = surface.controlVertexLimitOperator() * cube.points();
  const MatrixX3 local = (vertices.rowwise() - centre.transpose()) * axes;
  const MatrixX3 tessellation = (limitPoints(cube).rowwise() - centre.transpose()) * axes;
  for (int a = 0; a < 3; ++a) {
    EXPECT_NEAR(local.col(a).cwiseAbs().maxCoeff(), semiAxes(a), 1e-12) << "axis " << a;
    EXPECT_LE(tessellation.col(a).cwiseAbs().maxCoeff(), semiAxes(a) + 1e-12) << "axis " << a;
  }
}

// A sphere's radius is its limit surface's mean distance from the centre
// (measured on the same 4 x 4 tessellation that defines it: to rounding).
TEST(InitialModels, TheSphereHasItsMeanRadius) {
  const Vector3 centre(1, -1, 0.5);
  const ControlMesh sphere = initialSphere(centre, 3.0);
  const MatrixX3 points = tessellate(LimitSurface(sphere), sphere.points(), 4).points;
  EXPECT_NEAR((points.rowwise() - centre.transpose()).rowwise().norm().mean(), 3.0, 1e-12);
  EXPECT_THROW(initialSphere(centre, 0.0), Error);
  EXPECT_THROW(initialSphere(Vector3(NAN, 0, 0), 1.0), Error);
}

}  // namespace
}  // namespace dynsub
