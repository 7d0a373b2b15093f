#pragma once
// Dynamic subdivision solids (McDonnell and Qin §4.2-4.3, §5.1-5.2): the mass
// points d = A p of the lattice subdivided `levels` times carry the mass,
// damping and springs; the control points p move.
//
//   forces on the mass points  f_d = springs + virtual springs + rope - gamma d'
//   control accelerations      A1^T M A1 p1'' = A1^T f_d        (eq. 6)
// with M = m I and, when control points are fixed, p split into free p1 and
// fixed p2 (d = A1 p1 + A2 p2, §5.2: fixed points neither move nor enter the
// solve). A1^T M A1 is factored once per set of fixed points.
//
// Springs (§5.1): a normal spring along every edge of the subdivided lattice;
// a virtual spring from every corner m of every face to the midpoint of m's
// two neighbours in that face (a massless point: its reaction is shared half
// and half by those neighbours), resisting changes of the face's angles.
// Rest lengths are the lengths when the model is built or when
// resetRestLengths() is called (plasticity, §5.4).
//
// Integration: the paper's explicit scheme, p_{i+1} = p_i + p'_i dt,
// p'_{i+1} = p'_i + p''_i dt; or semi-implicit Euler (the new velocity moves
// the points), which is stable for steps several times larger.
// Units: mm, s; mass per mass point, stiffness N/mm, damping N s/mm.
#include <memory>
#include <vector>

#include "dynsub/SolidSubdivision.h"

namespace dynsub {

struct SolidMaterial {
  double mass = 1.0;               // per mass point
  double damping = 1.0;            // per mass point (settles the cubes fastest; measured)
  double springStiffness = 40.0;   // normal springs
  double virtualStiffness = 20.0;  // virtual springs
};

enum class SolidScheme { PaperExplicit, SemiImplicit };

class SolidModel {
 public:
  // Throws dynsub::Error for levels outside 0..4 or non-positive material values.
  SolidModel(const Lattice& control, int levels, const SolidMaterial& material = {});
  ~SolidModel();

  const Lattice& control() const { return control_; }
  const Lattice& dataLattice() const { return refined_.lattice; }  // topology of the mass points
  const SolidRefinement& refinement() const { return refined_; }
  const MatrixX3& controlPoints() const { return p_; }
  // Moves the control points (fixed ones too) and stops all motion; the
  // springs keep their rest lengths. Throws dynsub::Error for a wrong size or
  // non-finite points.
  void setControlPoints(const MatrixX3& points);
  MatrixX3 dataPoints() const;  // A p
  int springCount() const;
  int virtualSpringCount() const;

  void setMaterial(const SolidMaterial& material);  // while running: stiffness and damping change at once
  const SolidMaterial& material() const { return material_; }

  void fix(const std::vector<int>& controlPoints);
  void unfix(const std::vector<int>& controlPoints);
  const std::vector<bool>& fixed() const { return fixed_; }
  std::vector<int> fixedPoints() const;  // the fixed control points' indices

  // The rope tool: a spring from mass point `dataPoint` to `target`.
  void rope(int dataPoint, const Vector3& target, double stiffness);
  void releaseRope();
  int ropePoint() const { return ropePoint_; }  // -1 without a rope
  const Vector3& ropeTarget() const { return ropeTarget_; }
  int nearestDataPoint(const Vector3& point) const;  // the paper's linear search

  // Springs rest at their current lengths (the current shape becomes the rest shape).
  void resetRestLengths();

  // One time step of `dt` s. Throws dynsub::Error (and keeps the last state)
  // if the state would become non-finite: the step is too large for the stiffness.
  void step(double dt, SolidScheme scheme = SolidScheme::SemiImplicit);

  double kineticEnergy() const;  // of the mass points, 1/2 m |d'|^2
  double springEnergy() const;   // normal and virtual springs, N mm

 private:
  struct Springs;
  // Forces of the normal and virtual springs on the mass points `d`;
  // `energy` (if given) receives their stored energy, N mm.
  MatrixX3 springForces(const MatrixX3& d, double* energy = nullptr) const;
  void factor();

  Lattice control_;
  SolidRefinement refined_;
  SolidMaterial material_;
  MatrixX3 p_, v_;  // control points and their velocities
  std::vector<bool> fixed_;
  std::unique_ptr<Springs> springs_;
  int ropePoint_ = -1;
  Vector3 ropeTarget_ = Vector3::Zero();
  double ropeStiffness_ = 0;
  struct Solver;
  std::unique_ptr<Solver> solver_;
};

}  // namespace dynsub
