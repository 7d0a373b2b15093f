#pragma once
// Applied forces turned into generalized forces on the control vertices by
// virtual work (TVCG 1998 eq. 21, §3.2; ICCV 1998 eq. 17):
//   f_p = ∫∫ J^T f(u, v) du dv  ≈  sum_q w_q J_q^T f(s_q).
// Every function returns f_p as #control vertices x 3 (N), with points in mm.
//
// - Springs (eq. 27): a spring of stiffness k (N/mm) from a point d to the
//   surface point s(u0, v0) pulls with k (d - s); a point force, not a density.
// - Inflation: a pressure P (N/mm^2) along the limit normal, integrated over
//   the true surface area: f = P s_u x s_v per unit parametric area.
// - A force field (eq. 28 for images): a force per unit surface area (N/mm^2)
//   sampled at points in mm, integrated like the inflation.
#include <vector>

#include "dynsub/LimitSurface.h"

namespace dynsub {

struct Spring {
  ElementPoint attachment;
  Vector3 target;          // mm
  double stiffness = 1.0;  // N/mm
};

// Gauss points over every element with the limit operators there (built once
// per control-mesh topology; moving control points does not invalidate it).
struct SurfaceQuadrature {
  std::vector<ElementPoint> points;
  Eigen::VectorXd weights;  // parametric area per point (sums to elements x elementSize^2)
  SparseMatrix J, Ju, Jv;
};
// n x n Gauss-Legendre points per element (n in 1..16).
SurfaceQuadrature makeSurfaceQuadrature(const LimitSurface& surface, int pointsPerDirection = 3,
                                        double elementSize = 1.0);

// A force density field in physical space: N points in mm -> N forces (N/mm^2).
// Must return finite values for every point it is given.
class ForceField {
 public:
  virtual ~ForceField() = default;
  virtual MatrixX3 forcesAt(const MatrixX3& points) const = 0;
  // An upper bound of |df/dx| (N/mm^3) wherever the field changes fastest, or
  // 0 if unknown; it only serves to stabilize time integration (Integrator.h).
  virtual double slopeBound() const { return 0.0; }
};

// Generalized spring forces; `energy` (if given) receives sum k |d - s|^2 / 2 (N mm).
MatrixX3 springForces(const LimitSurface& surface, const MatrixX3& controlPoints, const std::vector<Spring>& springs,
                      double* energy = nullptr);
// sum k J_s^T J_s over the springs (#control by #control): minus the
// derivative of the spring forces with the attachments held fixed.
SparseMatrix springStiffness(const LimitSurface& surface, const std::vector<Spring>& springs);

MatrixX3 inflationForces(const SurfaceQuadrature& quadrature, const MatrixX3& controlPoints, double pressure);
// A pressure that varies over the surface: one value (N/mm^2) per quadrature point.
MatrixX3 pressureForces(const SurfaceQuadrature& quadrature, const MatrixX3& controlPoints,
                        const Eigen::VectorXd& pressures);
// A pressure along the surface's normal s_u x s_v that depends on where the
// surface is: N points in mm -> N pressures (N/mm^2; > 0 pushes outward, as
// inflation does). Must return finite values for every point it is given.
class PressureField {
 public:
  virtual ~PressureField() = default;
  virtual Eigen::VectorXd pressuresAt(const MatrixX3& points) const = 0;
  // How fast the pressure changes with position (N/mm^3): an upper bound of
  // |dp/dx| or an estimate of one, 0 if unknown. As ForceField's, it only
  // serves to stabilize time integration.
  virtual double slopeBound() const { return 0.0; }
};

// The field's forces, and the pressure's (if given) from the same evaluation
// of the surface at the quadrature points.
MatrixX3 fieldForces(const SurfaceQuadrature& quadrature, const MatrixX3& controlPoints, const ForceField& field,
                     const PressureField* pressure = nullptr);
// slope * sum_q w_q |s_u x s_v|_q J_q^T J_q (#control by #control): the
// stiffness of a field whose force changes by `slope` N/mm^3 in every
// direction, integrated over the surface at `controlPoints`.
SparseMatrix fieldStiffness(const SurfaceQuadrature& quadrature, const MatrixX3& controlPoints, double slope);

}  // namespace dynsub
