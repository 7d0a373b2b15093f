#pragma once
// The viewer's pulling spring: a force model that a user-interface thread
// changes while a simulation thread reads it, hence its own header (and lock).
#include <mutex>

#include "dynsub/ForceModel.h"

namespace dynsub {

// An interactive spring (modelling by pulling, TVCG §4.1): while a pull is
// on, a spring of stiffness k (N/mm) pulls the surface point that was nearest
// the grab point towards a target the user moves. The user-interface thread
// calls grab, moveTo and release while a simulation thread runs; when the
// surface is refined during a pull, the spring re-attaches to the point
// nearest its last attachment.
class PullForceModel final : public ForceModel {
 public:
  explicit PullForceModel(double stiffness);
  ~PullForceModel() override;

  void grab(const Vector3& surfacePoint, const Vector3& target);
  void moveTo(const Vector3& target);
  void release();
  bool active() const;
  // grab and moveTo calls so far: a simulation during which this changed
  // may have settled on a target that has moved since.
  unsigned moves() const;

  void beginLevel(const LimitSurface& surface, const SurfaceQuadrature& quadrature,
                  const MatrixX3& controlPoints) override;
  MatrixX3 generalizedForce(const MatrixX3& controlPoints, double& potential) override;
  // The spring's stiffness while a pull is on (a stiff explicit spring would
  // make the surface oscillate about the target instead of settling).
  SparseMatrix stabilizingStiffness(const MatrixX3& controlPoints) override;
  bool hasPotential() const override { return true; }

 private:
  // With the mutex held: attach to the surface point nearest anchor_ unless attached.
  void attachNearAnchor(const MatrixX3& controlPoints);

  double stiffness_;
  mutable std::mutex mutex_;
  bool active_ = false;
  bool attached_ = false;
  Vector3 anchor_ = Vector3::Zero();  // where to attach (mm)
  Vector3 target_ = Vector3::Zero();
  unsigned moves_ = 0;
  ElementPoint attachment_;
  const LimitSurface* surface_ = nullptr;
};

}  // namespace dynsub
