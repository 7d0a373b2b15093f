#pragma once
// The equilibrium K p = f_p(p) of TVCG 1998 eq. 17 (the state the papers'
// dynamics settle in, with p'' = p' = 0) reached directly, by damped Newton
// steps instead of time steps:
//   (K + H) d = f_p(p) - K p,   p <- p + lambda d,
// with H >= 0 an approximation of -df_p/dp, the forces' tangent stiffness
// (ForceModel::addTangentStiffness). Whatever H is, a step is zero exactly
// where K p = f_p, so the fixed points are the papers' equilibria; H sets only
// how fast they are reached.
//
// Why it needs tens of solves where the time-stepping schemes need hundreds:
// data springs attach to the *nearest* surface point, so at equilibrium their
// pull is normal to the surface and nothing but the surface's own elasticity
// holds it tangentially. The time-stepping schemes stabilize the springs with
// their full stiffness k J^T J (Integrator.h), which also holds every
// tangential slide back by k against an elasticity often a thousand times
// weaker: the surface creeps along itself one small step at a time. Here a
// spring contributes k J^T (n n^T + e (I - n n^T)) J instead, the
// tangent-plane stiffness of squared-distance minimization (Pottmann et al.'s
// tangent-distance step) with a small tangential share e, so the
// normal motion is taken in one step and the tangential one is left to K.
//
// The system couples x, y and z: unknown 3 v + a is coordinate a of control
// vertex v (3N by 3N). Its sparsity is every pair of control vertices sharing
// an element, fixed while the control mesh's topology is: it is analysed once
// per level and factored numerically (sparse LDL^T) at every step.
#include <memory>
#include <vector>

#include "dynsub/LimitSurface.h"
#include "dynsub/PhysicalMatrices.h"
#include "dynsub/TangentStiffness.h"

namespace dynsub {

class ForceModel;

class StaticSolver {
 public:
  // stiffness: K (N by N); fixed: control vertices that do not move.
  StaticSolver(const LimitSurface& surface, const SymmetricMatrix& stiffness, const std::vector<int>& fixed);
  ~StaticSolver();

  // The Newton direction d (#control x 3) at `controlPoints` for the residual
  // f_p - K p (#control x 3), with H from the forces' tangent stiffness there,
  // or, with `isotropic`, from their stabilizing stiffness on x, y and z alike
  // (for springs the classic step to the nearest points, which never raises
  // their energy: the fallback where a Newton step lowers nothing).
  // A matrix that will not factor as positive definite is regularized (a
  // diagonal shift growing 1000-fold, up to 1e-2 of the mean diagonal); if it
  // still fails, throws dynsub::Error.
  MatrixX3 direction(const std::vector<ForceModel*>& forces, const MatrixX3& controlPoints,
                     const MatrixX3& residual, bool isotropic = false);
  // Diagonal shifts applied over all factorizations (0 when none was needed).
  int regularizations() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace dynsub
