#include "dynsub/Forces.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "dynsub/ApplyOperator.h"
#include "dynsub/Error.h"
#include "dynsub/GaussLegendre.h"

namespace dynsub {

SurfaceQuadrature makeSurfaceQuadrature(const LimitSurface& surface, int pointsPerDirection, double elementSize) {
  if (pointsPerDirection < 1 || pointsPerDirection > 16) {
    throw Error("surface quadrature takes 1..16 points per direction, got " + std::to_string(pointsPerDirection));
  }
  const QuadratureRule rule = gaussLegendre(pointsPerDirection);
  SurfaceQuadrature q;
  const int perElement = pointsPerDirection * pointsPerDirection;
  q.weights.resize(static_cast<Eigen::Index>(surface.elementCount()) * perElement);
  for (int e = 0; e < surface.elementCount(); ++e) {
    for (int j = 0; j < pointsPerDirection; ++j) {
      for (int i = 0; i < pointsPerDirection; ++i) {
        q.weights(static_cast<Eigen::Index>(q.points.size())) =
            rule.weights[i] * rule.weights[j] * elementSize * elementSize;
        q.points.push_back(ElementPoint{e, rule.nodes[i], rule.nodes[j]});
      }
    }
  }
  LimitOperators operators = surface.operators(q.points, 1);  // J, J_u and J_v only
  // Swapped in: Eigen 3.4's sparse matrices have no move, so std::move would
  // copy them (three operators of a row per quadrature point).
  q.J.swap(operators.J);
  q.Ju.swap(operators.Ju);
  q.Jv.swap(operators.Jv);
  return q;
}

MatrixX3 springForces(const LimitSurface& surface, const MatrixX3& controlPoints, const std::vector<Spring>& springs,
                      double* energy) {
  std::vector<ElementPoint> at;
  at.reserve(springs.size());
  for (const Spring& s : springs) at.push_back(s.attachment);
  const SparseMatrix J = surface.limitOperator(at);
  MatrixX3 pull = applyOperator(J, controlPoints);  // s at the attachments
  double total = 0.0;
  for (size_t i = 0; i < springs.size(); ++i) {
    const Vector3 stretch = springs[i].target - pull.row(i).transpose();
    total += 0.5 * springs[i].stiffness * stretch.squaredNorm();
    pull.row(i) = springs[i].stiffness * stretch.transpose();
  }
  if (energy) *energy = total;
  return J.transpose() * pull;
}

SparseMatrix springStiffness(const LimitSurface& surface, const std::vector<Spring>& springs) {
  std::vector<ElementPoint> at;
  Eigen::VectorXd k(springs.size());
  for (size_t i = 0; i < springs.size(); ++i) {
    at.push_back(springs[i].attachment);
    k(i) = springs[i].stiffness;
  }
  const SparseMatrix J = surface.limitOperator(at);
  return SparseMatrix(J.transpose() * k.asDiagonal() * J);
}

namespace {

// sum_q w_q J_q^T (f_q |s_u x s_v|_q) with f given per point, or P n for inflation.
MatrixX3 integrate(const SurfaceQuadrature& q, const MatrixX3& densityTimesArea) {
  return applyTransposed(q.J, q.weights.asDiagonal() * densityTimesArea);
}

// |s_u x s_v| at every quadrature point: surface area per unit parametric area.
Eigen::VectorXd areaElements(const MatrixX3& su, const MatrixX3& sv) {
  Eigen::VectorXd area(su.rows());
  for (Eigen::Index i = 0; i < su.rows(); ++i) area(i) = su.row(i).cross(sv.row(i)).norm();
  return area;
}

}  // namespace

MatrixX3 inflationForces(const SurfaceQuadrature& q, const MatrixX3& controlPoints, double pressure) {
  if (!std::isfinite(pressure)) throw Error("inflation pressure is not finite");
  return pressureForces(q, controlPoints, Eigen::VectorXd::Constant(q.J.rows(), pressure));
}

MatrixX3 pressureForces(const SurfaceQuadrature& q, const MatrixX3& controlPoints, const Eigen::VectorXd& pressures) {
  if (pressures.size() != q.J.rows()) throw Error("internal: one pressure per quadrature point expected");
  if (!pressures.allFinite()) throw Error("a pressure is not finite");
  const MatrixX3 su = applyOperator(q.Ju, controlPoints), sv = applyOperator(q.Jv, controlPoints);
  MatrixX3 area(su.rows(), 3);
  for (Eigen::Index i = 0; i < su.rows(); ++i) {
    area.row(i) = pressures(i) * su.row(i).cross(sv.row(i));
  }
  return integrate(q, area);
}

MatrixX3 fieldForces(const SurfaceQuadrature& q, const MatrixX3& controlPoints, const ForceField& field,
                     const PressureField* pressure) {
  MatrixX3 positions, su, sv;
  applyOperators(q.J, q.Ju, q.Jv, controlPoints, positions, su, sv);  // one pass: they share a pattern
  MatrixX3 forces = field.forcesAt(positions);
  if (forces.rows() != positions.rows()) {
    throw Error("force field returned " + std::to_string(forces.rows()) + " forces for " +
                std::to_string(positions.rows()) + " points");
  }
  if (!forces.allFinite()) throw Error("force field returned a non-finite force");
  MatrixX3 area = areaElements(su, sv).asDiagonal() * forces;
  if (pressure) {
    const Eigen::VectorXd pressures = pressure->pressuresAt(positions);
    if (pressures.size() != positions.rows()) {
      throw Error("pressure field returned " + std::to_string(pressures.size()) + " pressures for " +
                  std::to_string(positions.rows()) + " points");
    }
    if (!pressures.allFinite()) throw Error("pressure field returned a non-finite pressure");
    for (Eigen::Index i = 0; i < positions.rows(); ++i)
      if (pressures(i) != 0.0) area.row(i) += pressures(i) * su.row(i).cross(sv.row(i));
  }
  return integrate(q, area);
}

SparseMatrix fieldStiffness(const SurfaceQuadrature& q, const MatrixX3& controlPoints, double slope) {
  const MatrixX3 su = applyOperator(q.Ju, controlPoints), sv = applyOperator(q.Jv, controlPoints);
  const Eigen::VectorXd weights = slope * q.weights.cwiseProduct(areaElements(su, sv));
  // One element's quadrature points share its columns (J, J_u and J_v
  // have one pattern), so their rank-one terms are summed in a dense block
  // per element and only the block goes into the triplets, which costs less
  // than Eigen's sparse product J^T W J.
  const int* outer = q.J.outerIndexPtr();
  const int* inner = q.J.innerIndexPtr();
  const double* values = q.J.valuePtr();
  std::vector<Eigen::Triplet<double>> triplets;
  Eigen::MatrixXd block;
  for (Eigen::Index first = 0, last = 0; first < q.J.rows(); first = last) {
    const int m = outer[first + 1] - outer[first];
    const int* columns = inner + outer[first];
    for (last = first + 1; last < q.J.rows(); ++last) {
      if (outer[last + 1] - outer[last] != m || !std::equal(columns, columns + m, inner + outer[last])) break;
    }
    block.setZero(m, m);
    for (Eigen::Index r = first; r < last; ++r) {
      const Eigen::Map<const Eigen::VectorXd> row(values + outer[r], m);
      block.selfadjointView<Eigen::Lower>().rankUpdate(row, weights(r));
    }
    for (int j = 0; j < m; ++j) {
      for (int i = j; i < m; ++i) {
        if (block(i, j) == 0.0) continue;
        triplets.emplace_back(columns[i], columns[j], block(i, j));
        if (i != j) triplets.emplace_back(columns[j], columns[i], block(i, j));
      }
    }
  }
  SparseMatrix result(q.J.cols(), q.J.cols());
  result.setFromTriplets(triplets.begin(), triplets.end());
  return result;
}

}  // namespace dynsub
