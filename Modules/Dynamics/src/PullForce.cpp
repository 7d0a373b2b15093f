#include "dynsub/PullForce.h"

#include <cmath>
#include <string>

#include "dynsub/ApplyOperator.h"
#include "dynsub/ClosestPoint.h"
#include "dynsub/Error.h"
#include "dynsub/StaticSolver.h"

namespace dynsub {

PullForceModel::PullForceModel(double stiffness) : stiffness_(stiffness) {
  if (!(std::isfinite(stiffness) && stiffness > 0)) throw Error("the pulling spring's stiffness must be finite and > 0");
}

PullForceModel::~PullForceModel() = default;

void PullForceModel::grab(const Vector3& surfacePoint, const Vector3& target) {
  std::lock_guard<std::mutex> lock(mutex_);
  active_ = surfacePoint.allFinite() && target.allFinite();
  attached_ = false;
  anchor_ = surfacePoint;
  target_ = target;
  ++moves_;
}

void PullForceModel::moveTo(const Vector3& target) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (target.allFinite()) {
    target_ = target;
    ++moves_;
  }
}

unsigned PullForceModel::moves() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return moves_;
}

void PullForceModel::release() {
  std::lock_guard<std::mutex> lock(mutex_);
  active_ = false;
}

bool PullForceModel::active() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return active_;
}

void PullForceModel::beginLevel(const LimitSurface& surface, const SurfaceQuadrature&, const MatrixX3&) {
  std::lock_guard<std::mutex> lock(mutex_);
  surface_ = &surface;
  attached_ = false;  // element numbers changed; re-attach near anchor_
}

void PullForceModel::attachNearAnchor(const MatrixX3& controlPoints) {
  if (attached_) return;
  ClosestPointLocator locator(*surface_);
  locator.update(controlPoints);
  attachment_ = locator.find(anchor_).point;
  attached_ = true;
}

MatrixX3 PullForceModel::generalizedForce(const MatrixX3& controlPoints, double& potential) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (!active_ || !surface_) return MatrixX3::Zero(controlPoints.rows(), 3);
  attachNearAnchor(controlPoints);
  double energy = 0.0;
  const MatrixX3 force = springForces(*surface_, controlPoints, {Spring{attachment_, target_, stiffness_}}, &energy);
  potential += energy;
  // Where the spring holds the surface now: the place to re-attach after a refinement.
  anchor_ = (surface_->limitOperator({attachment_}) * controlPoints).row(0).transpose();
  return force;
}

SparseMatrix PullForceModel::stabilizingStiffness(const MatrixX3& controlPoints) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (!active_ || !surface_) return SparseMatrix();
  attachNearAnchor(controlPoints);
  return springStiffness(*surface_, {Spring{attachment_, target_, stiffness_}});
}

}  // namespace dynsub
