#include "dynsub/InitialModels.h"

#include <cmath>
#include <sstream>

#include <Eigen/Eigenvalues>

#include "dynsub/Error.h"
#include "dynsub/LimitSurface.h"
#include "dynsub/StandardMeshes.h"
#include "dynsub/Tessellation.h"

namespace dynsub {
namespace {

struct Principal {
  Vector3 mean;
  Eigen::Matrix3d axes;    // columns: unit eigenvectors, decreasing variance, right-handed
  Vector3 variances;       // decreasing
};

Principal principalAxes(const MatrixX3& points) {
  Principal p;
  p.mean = points.colwise().mean().transpose();
  const MatrixX3 centred = points.rowwise() - p.mean.transpose();
  const Eigen::Matrix3d covariance = centred.transpose() * centred / static_cast<double>(points.rows());
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(covariance);
  for (int i = 0; i < 3; ++i) {
    p.variances(i) = std::max(0.0, solver.eigenvalues()(2 - i));
    p.axes.col(i) = solver.eigenvectors().col(2 - i);
  }
  if (p.axes.determinant() < 0.0) p.axes.col(2) *= -1.0;  // keep orientation (outward normals)
  return p;
}

// The limit positions of the control vertices.
MatrixX3 limitPositions(const ControlMesh& mesh) {
  const LimitSurface surface(mesh);
  return surface.controlVertexLimitOperator() * mesh.points();
}

// The one placement of the cube: its control points scaled along the
// coordinate axes, turned onto `axes` and moved to `centre`.
ControlMesh placeCube(ControlMesh cube, const Vector3& scale, const Matrix3& axes, const Vector3& centre) {
  cube.setPoints(((cube.points() * scale.asDiagonal()) * axes.transpose()).rowwise() + centre.transpose());
  return cube;
}

}  // namespace

void checkPointCloud(const MatrixX3& points, const std::string& source) {
  if (points.rows() < 4) {
    throw Error(source, "has " + std::to_string(points.rows()) + " points; a surface needs at least 4");
  }
  for (Eigen::Index i = 0; i < points.rows(); ++i) {
    if (!points.row(i).allFinite()) throw Error(source, "point " + std::to_string(i + 1) + " is not finite");
    // Squared distances of coordinates near 1e154 overflow, and the test of
    // coincidence below would see NaN.
    const std::string beyond = beyondLargestCoordinate(points.row(i).transpose());
    if (!beyond.empty()) throw Error(source, "point " + std::to_string(i + 1) + " " + beyond);
  }
  // Likewise, spans below this have squared distances that underflow to 0.
  const double span = (points.colwise().maxCoeff() - points.colwise().minCoeff()).maxCoeff();
  if (span > 0 && span < kSmallestSpan) {
    std::ostringstream message;
    message << "the points span only " << span << " mm, less than the " << kSmallestSpan
            << " mm DynSub works with; coordinates are in mm";
    throw Error(source, message.str());
  }
  switch (spannedDimensions(points)) {
    case 0: throw Error(source, "all points coincide");
    case 1: throw Error(source, "all points lie on a line");
    case 2: throw Error(source, "all points lie on a plane");
    default: return;
  }
}

int spannedDimensions(const MatrixX3& points) {
  const Principal p = principalAxes(points);
  if (!(p.variances(0) > 0.0)) return 0;
  // Relative to the largest spread: 1e-10 of the variance is 1e-5 of the
  // size, above the rounding of coordinates written to 6 digits (a line so
  // written scatters by up to 1e-6 of its length).
  if (p.variances(1) <= 1e-10 * p.variances(0)) return 1;
  if (p.variances(2) <= 1e-10 * p.variances(0)) return 2;
  return 3;
}

ControlMesh cubeInEllipsoid(const Vector3& centre, const Matrix3& axes, const Vector3& semiAxes) {
  const ControlMesh cube = makeCube98();
  // The cube's limit surface spans [-h, h]^3 around the origin.
  const double h = limitPositions(cube).cwiseAbs().maxCoeff();
  return placeCube(cube, semiAxes / h, axes, centre);
}

ControlMesh initialModel(const MatrixX3& points, InitialShape shape, double fraction) {
  if (!(fraction > 0 && fraction <= 1)) throw Error("the initial model's fraction of the data's extent must be in (0, 1]");
  const Principal p = principalAxes(points);
  if (shape == InitialShape::Sphere) {
    Vector3 semiAxes;
    for (int i = 0; i < 3; ++i) semiAxes(i) = fraction * std::sqrt(3.0 * p.variances(i));
    return cubeInEllipsoid(p.mean, p.axes, semiAxes);
  }
  // Torus: axis along the least-variance direction (third axis).
  const MatrixX3 local = (points.rowwise() - p.mean.transpose()) * p.axes;
  const Eigen::VectorXd rho = local.leftCols(2).rowwise().norm();
  const double ring = rho.mean();
  const double tube = std::sqrt(((rho.array() - ring).square() + local.col(2).array().square()).mean());
  ControlMesh torus = makeTorus32();
  // The standard torus: ring radius 1, tube 0.5 (control mesh); measure its limit.
  const MatrixX3 limit = limitPositions(torus);
  const Eigen::VectorXd limitRho = limit.leftCols(2).rowwise().norm();
  const double limitRing = limitRho.mean();
  const double limitTube = std::sqrt(((limitRho.array() - limitRing).square() + limit.col(2).array().square()).mean());
  MatrixX3 control = torus.points();
  for (Eigen::Index i = 0; i < control.rows(); ++i) {
    const double r = control.row(i).head<2>().norm();
    const double radial = ring + (r - limitRing) * 0.5 * tube / limitTube;
    const double height = control(i, 2) * 0.5 * tube / limitTube;
    control.row(i).head<2>() *= radial / r;
    control(i, 2) = height;
  }
  torus.setPoints((control * p.axes.transpose()).rowwise() + p.mean.transpose());
  return torus;
}

ControlMesh initialSphere(const Vector3& centre, double radius) {
  if (!(radius > 0) || !std::isfinite(radius) || !centre.allFinite())
    throw Error("the initial sphere needs a finite centre and a radius > 0 mm");
  // The cube's limit is not round: its corners reach beyond its half-extent
  // along the axes. A sphere's radius is its mean radius m.
  const ControlMesh cube = makeCube98();
  const double m = tessellate(LimitSurface(cube), cube.points(), 4).points.rowwise().norm().mean();
  return placeCube(cube, Vector3::Constant(radius / m), Matrix3::Identity(), centre);
}

}  // namespace dynsub
