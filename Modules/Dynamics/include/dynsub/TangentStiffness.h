#pragma once
// The stiffness a static step solves with (StaticSolver.h), which the force
// models add their tangent stiffness to (ForceModel::addTangentStiffness).
#include <memory>

#include "dynsub/LimitSurface.h"
#include "dynsub/PhysicalMatrices.h"

namespace dynsub {

// A 3N by 3N symmetric stiffness on the pattern of a surface's elements,
// filled in place: K on x, y and z, then per-point blocks (J_q^T J_q) (x) B.
class TangentStiffness {
 public:
  // The surface must outlive this.
  explicit TangentStiffness(const LimitSurface& surface);
  ~TangentStiffness();

  // Starts anew with `scalar` (N by N) on x, y and z alike.
  void reset(const SymmetricMatrix& scalar);
  // Starts anew with the last reset()'s `scalar`, from a copy of the values
  // it gave (the Newton steps of one level all start from K).
  void resetToLast();
  // Adds S (x) I_3 for a symmetric N by N S joining only control vertices
  // that share an element (springs' and fields' J^T W J are such).
  void addScalar(const SparseMatrix& scalar);
  // Adds (J_q^T J_q) (x) B: a stiffness B (symmetric 3 x 3, N/mm) acting on
  // the limit position at q. `weights`, when given, is q's
  // LimitSurface::positionStencil, taken already by the caller; it must live
  // until the next matrix().
  void addPoint(const ElementPoint& q, const Eigen::Matrix3d& block, const Eigen::RowVectorXd* weights = nullptr);
  // The matrix with every addition made, its lower triangle alone stored
  // (the solvers read no other); the caller may change values in place
  // until the next reset.
  SymmetricMatrix& matrix();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace dynsub
