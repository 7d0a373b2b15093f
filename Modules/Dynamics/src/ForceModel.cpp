#include "dynsub/ForceModel.h"

#include <algorithm>
#include <cmath>
#include <random>
#include <string>

#include "dynsub/ApplyOperator.h"
#include "dynsub/ClosestPoint.h"
#include "dynsub/Error.h"
#include "dynsub/ParallelFor.h"
#include "dynsub/TangentStiffness.h"

namespace dynsub {

SparseMatrix ForceModel::stabilizingStiffness(const MatrixX3&) { return SparseMatrix(); }

void ForceModel::addTangentStiffness(const MatrixX3& controlPoints, TangentStiffness& into) {
  const SparseMatrix s = stabilizingStiffness(controlPoints);
  if (s.size() > 0) into.addScalar(s);
}

SpringForceModel::SpringForceModel(MatrixX3 targets, Eigen::VectorXd stiffness, Attach attach)
    : allTargets_(std::move(targets)), allStiffness_(std::move(stiffness)), attach_(attach) {
  if (allTargets_.rows() != allStiffness_.size()) {
    throw Error("got " + std::to_string(allStiffness_.size()) + " spring stiffnesses for " +
                std::to_string(allTargets_.rows()) + " springs");
  }
  if (!allTargets_.allFinite()) throw Error("a spring target is not finite");
  for (Eigen::Index i = 0; i < allStiffness_.size(); ++i) {
    if (!(std::isfinite(allStiffness_(i)) && allStiffness_(i) > 0.0)) {
      throw Error("spring " + std::to_string(i) + " has stiffness " + std::to_string(allStiffness_(i)) +
                  " (expected a finite value > 0)");
    }
  }
  targets_ = allTargets_;
  stiffness_ = allStiffness_;
}

SpringForceModel::~SpringForceModel() = default;

void SpringForceModel::beginLevel(const LimitSurface& surface, const SurfaceQuadrature&,
                                  const MatrixX3& controlPoints) {
  surface_ = &surface;
  locator_ = std::make_unique<ClosestPointLocator>(surface);
  const Eigen::Index all = allTargets_.rows();
  const double wanted = samplePerElement_ * surface.elementCount();
  const Eigen::Index sample =
      samplePerElement_ > 0 && wanted < all ? std::max<Eigen::Index>(1, static_cast<Eigen::Index>(wanted)) : all;
  if (sample != targets_.rows()) {
    targets_.resize(sample, 3);
    stiffness_.resize(sample);
    const double share = static_cast<double>(all) / static_cast<double>(sample);
    for (Eigen::Index i = 0; i < sample; ++i) {
      const Eigen::Index j = sample == all ? i : sampleOrder_[static_cast<size_t>(i)];
      targets_.row(i) = allTargets_.row(j);
      stiffness_(i) = sample == all ? allStiffness_(j) : share * allStiffness_(j);
    }
  }
  springs_.clear();  // attachments of the previous level mean nothing on the new surface
  tracked_.clear();
  attach(controlPoints);
  acceptState();
}

void SpringForceModel::acceptState() {
  tracked_.resize(springs_.size());
  for (size_t i = 0; i < springs_.size(); ++i) tracked_[i] = springs_[i].attachment;
}

void SpringForceModel::attach(const MatrixX3& controlPoints) {
  locator_->update(controlPoints);
  // Track the last accepted state's attachments where there are some (same level).
  const std::vector<ClosestPoint> nearest = tracked_.size() == static_cast<size_t>(targets_.rows())
                                                ? locator_->findAll(targets_, tracked_)
                                                : locator_->findAll(targets_);
  springs_.resize(nearest.size());
  positions_.resize(targets_.rows(), 3);
  normals_.resize(targets_.rows(), 3);
  for (size_t i = 0; i < nearest.size(); ++i) {
    springs_[i] = Spring{nearest[i].point, targets_.row(i).transpose(), stiffness_(i)};
    positions_.row(static_cast<Eigen::Index>(i)) = nearest[i].position.transpose();
    normals_.row(static_cast<Eigen::Index>(i)) = nearest[i].normal.transpose();
  }
  // The special elements' position stencils at the attachments, on both
  // cores: the force and the static scheme's tangent stiffness both take
  // them, so they are evaluated once, here.
  const Eigen::Index count = static_cast<Eigen::Index>(springs_.size());
  stencils_.resize(springs_.size());
  parallelFor(count, threadsWorth(count), [&](Eigen::Index i) {
    const ElementPoint& q = springs_[i].attachment;
    if (surface_->elementType(q.element) == ElementType::Normal) {
      stencils_[i].resize(0);
    } else {
      stencils_[i] = surface_->positionStencil(q);
    }
  });
}

Eigen::VectorXd SpringForceModel::signedLengths() const {
  Eigen::VectorXd signedLength(positions_.rows());
  for (Eigen::Index i = 0; i < positions_.rows(); ++i) {
    signedLength(i) =
        signedDistance(targets_.row(i).transpose(), positions_.row(i).transpose(), normals_.row(i).transpose());
  }
  return signedLength;
}

MatrixX3 SpringForceModel::generalizedForce(const MatrixX3& controlPoints, double& potential) {
  if (attach_ == Attach::NearestAtLevelStart) {
    std::vector<ElementPoint> at;
    at.reserve(springs_.size());
    for (const Spring& s : springs_) at.push_back(s.attachment);
    const SparseMatrix J = surface_->limitOperator(at);
    const MatrixX3 stretch = targets_ - applyOperator(J, controlPoints);  // d - s per spring
    lengths_ = stretch.rowwise().norm();
    potential += 0.5 * stiffness_.dot(lengths_.cwiseAbs2());
    return J.transpose() * (stiffness_.asDiagonal() * stretch);
  }
  attach(controlPoints);
  MatrixX3 stretch = targets_ - positions_;  // the locator's positions at these control points
  lengths_ = stretch.rowwise().norm();
  if (deadZone_ > 0) {
    const Eigen::ArrayXd beyond = (lengths_.array() - deadZone_).max(0.0);
    potential += 0.5 * (stiffness_.array() * beyond.square()).sum();
    stretch.array().colwise() *= (lengths_.array() > deadZone_).select(beyond / lengths_.array(), 0.0);
  } else {
    potential += 0.5 * stiffness_.dot(lengths_.cwiseAbs2());
  }
  // J^T k (d - s), without building J: pulls on a normal element's 16 grid
  // points go back through the patch operator in one product; the few on
  // special elements through their stencils.
  const SparseMatrix& patches = locator_->patchOperator();
  MatrixX3 onGrids = MatrixX3::Zero(patches.rows(), 3);
  MatrixX3 force = MatrixX3::Zero(controlPoints.rows(), 3);
  for (size_t i = 0; i < springs_.size(); ++i) {
    const ElementPoint& q = springs_[i].attachment;
    const Eigen::Index row = static_cast<Eigen::Index>(i);
    const Eigen::RowVector3d pull = stiffness_(row) * stretch.row(row);
    if (surface_->elementType(q.element) == ElementType::Normal) {
      onGrids.middleRows<16>(16 * static_cast<Eigen::Index>(q.element)).noalias() +=
          bicubicBsplineWeights(q.u, q.v).row(0).transpose() * pull;
    } else {
      const Eigen::RowVectorXd& w = stencils_[i];
      const std::vector<int>& columns = surface_->elementColumns(q.element);
      for (size_t c = 0; c < columns.size(); ++c) force.row(columns[c]) += w(static_cast<Eigen::Index>(c)) * pull;
    }
  }
  force.noalias() += patches.transpose() * onGrids;
  return force;
}

void SpringForceModel::setDeadZone(double zone) {
  if (!(zone >= 0) || !std::isfinite(zone)) throw Error("a spring's dead zone must be a finite number >= 0 mm");
  deadZone_ = zone;
}

void SpringForceModel::setSamplePerElement(double perElement) {
  if (!(perElement >= 0) || !std::isfinite(perElement)) {
    throw Error("the springs per element must be a finite number >= 0");
  }
  samplePerElement_ = perElement;
  if (perElement == 0 || !sampleOrder_.empty()) return;
  // Fisher-Yates with a fixed seed: the same sample on every run and machine.
  sampleOrder_.resize(static_cast<size_t>(allTargets_.rows()));
  for (size_t i = 0; i < sampleOrder_.size(); ++i) sampleOrder_[i] = static_cast<Eigen::Index>(i);
  std::mt19937_64 random(20261205);
  for (size_t i = sampleOrder_.size(); i > 1; --i) std::swap(sampleOrder_[i - 1], sampleOrder_[random() % i]);
}

SparseMatrix SpringForceModel::stabilizingStiffness(const MatrixX3&) { return springStiffness(*surface_, springs_); }

void SpringForceModel::addTangentStiffness(const MatrixX3& controlPoints, TangentStiffness& into) {
  // Springs held at their attachments: k J^T J is the exact derivative.
  if (attach_ == Attach::NearestAtLevelStart) return ForceModel::addTangentStiffness(controlPoints, into);
  // The normals are the last evaluation's, the state the Newton step starts from.
  for (size_t i = 0; i < springs_.size(); ++i) {
    const Spring& spring = springs_[i];
    const Vector3 normal = normals_.row(static_cast<Eigen::Index>(i)).transpose();
    Eigen::Matrix3d block = spring.stiffness * Eigen::Matrix3d::Identity();
    // Where the normal is undefined (a degenerate point) the spring stays isotropic.
    if (normal.squaredNorm() > 0.0) {
      block = spring.stiffness * ((1.0 - kTangentialShare) * normal * normal.transpose() +
                                  kTangentialShare * Eigen::Matrix3d::Identity());
    }
    // The stencil attach() took at this attachment (special elements only).
    into.addPoint(spring.attachment, block, stencils_[i].size() > 0 ? &stencils_[i] : nullptr);
  }
}

InflationForceModel::InflationForceModel(double pressure) : pressure_(pressure) {
  if (!std::isfinite(pressure)) throw Error("inflation pressure is not finite");
}

void InflationForceModel::beginLevel(const LimitSurface&, const SurfaceQuadrature& quadrature, const MatrixX3&) {
  quadrature_ = &quadrature;
}

MatrixX3 InflationForceModel::generalizedForce(const MatrixX3& controlPoints, double&) {
  return inflationForces(*quadrature_, controlPoints, pressure_);
}

void FieldForceModel::beginLevel(const LimitSurface&, const SurfaceQuadrature& quadrature, const MatrixX3&) {
  quadrature_ = &quadrature;
}

MatrixX3 FieldForceModel::generalizedForce(const MatrixX3& controlPoints, double&) {
  return fieldForces(*quadrature_, controlPoints, field_, pressure_);
}

SparseMatrix FieldForceModel::stabilizingStiffness(const MatrixX3& controlPoints) {
  const double slope = field_.slopeBound() + (pressure_ ? pressure_->slopeBound() : 0.0);
  if (!(slope > 0.0)) return SparseMatrix();
  return fieldStiffness(*quadrature_, controlPoints, slope);
}

}  // namespace dynsub
