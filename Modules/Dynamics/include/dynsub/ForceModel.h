#pragma once
// Forces a simulation re-evaluates every time step (Simulation.h), built on
// the functions of Forces.h.
#include <memory>
#include <vector>

#include "dynsub/Forces.h"

namespace dynsub {

class ClosestPointLocator;
class TangentStiffness;

class ForceModel {
 public:
  virtual ~ForceModel() = default;
  // A level starts: the control mesh (and so the surface and its quadrature)
  // changed. The references stay valid until the next beginLevel.
  virtual void beginLevel(const LimitSurface& surface, const SurfaceQuadrature& quadrature,
                          const MatrixX3& controlPoints) = 0;
  // f_p at the control points (#control x 3); adds the force's potential
  // energy (N mm) to `potential` where it has one.
  virtual MatrixX3 generalizedForce(const MatrixX3& controlPoints, double& potential) = 0;
  // The state of the last generalizedForce call is the one the simulation
  // goes on from. The static scheme also evaluates trial states it may
  // reject; forces that track the surface (springs re-attaching to the
  // nearest points) track it from accepted states only, so that a rejected
  // trial leaves no trace.
  virtual void acceptState() {}
  // A stiffness S >= 0 of the force near the current state, used only to
  // stabilize time integration (Integrator.h); empty (0 x 0) if none.
  virtual SparseMatrix stabilizingStiffness(const MatrixX3& controlPoints);
  // Adds an approximation of -d f_p / d p at the state of the last
  // generalizedForce call, for the static scheme's Newton steps
  // (StaticSolver.h). By default the stabilizing stiffness on x, y and z alike.
  virtual void addTangentStiffness(const MatrixX3& controlPoints, TangentStiffness& into);
  // True when generalizedForce adds the force's whole potential energy, so
  // that the total energy is what the static scheme's steps must lower.
  virtual bool hasPotential() const { return false; }
};

// Springs from fixed points in space to the surface (TVCG eq. 27).
//  - NearestEachStep: every step each spring re-attaches to the point of the
//    limit surface nearest its target (shape recovery, §4.2);
//  - NearestAtLevelStart: springs attach to the nearest points when a level
//    starts and then pull those surface points (modeling, §4.1).
class SpringForceModel final : public ForceModel {
 public:
  enum class Attach { NearestEachStep, NearestAtLevelStart };
  // targets: #springs x 3 (mm); stiffness: one per spring (N/mm), > 0.
  SpringForceModel(MatrixX3 targets, Eigen::VectorXd stiffness, Attach attach);
  ~SpringForceModel() override;

  void beginLevel(const LimitSurface& surface, const SurfaceQuadrature& quadrature,
                  const MatrixX3& controlPoints) override;
  MatrixX3 generalizedForce(const MatrixX3& controlPoints, double& potential) override;
  void acceptState() override;
  SparseMatrix stabilizingStiffness(const MatrixX3& controlPoints) override;
  // NearestEachStep: k (n n^T + kTangentialShare (I - n n^T)) at each
  // attachment, n the limit normal there (the tangent-plane stiffness of
  // StaticSolver.h); NearestAtLevelStart: k J^T J, the exact derivative.
  void addTangentStiffness(const MatrixX3& controlPoints, TangentStiffness& into) override;
  bool hasPotential() const override { return true; }

  // The share of a spring's stiffness kept tangentially in the static
  // scheme: enough to keep each step's slide along the surface bounded where
  // the surface's elasticity is weak (with none, Newton steps slide the
  // control mesh along itself by up to the model's size and the energy rises),
  // small enough not to hold the slide back. Chosen on the synthetic tuning
  // clouds (Tools/tuning_clouds.py), not on CGAL's scans, which stay a test set.
  static constexpr double kTangentialShare = 0.01;

  // Spring lengths (distances target - attachment, mm) at the last evaluation.
  const Eigen::VectorXd& lengths() const { return lengths_; }
  // NearestEachStep only: each length signed along the limit normal at the
  // attachment (positive where the target is on the normal's side), at the
  // last evaluation; the plain length where the normal is undefined.
  Eigen::VectorXd signedLengths() const;

  // NearestEachStep only: a spring pulls with k (length - zone) beyond `zone`
  // mm and not at all within it, for targets known only to about that much
  // (an expert's clicks). 0 (the default) is the plain spring.
  void setDeadZone(double zone);

  // NearestEachStep only: on a surface of E elements with more than
  // perElement * E targets, only a fixed sample of perElement * E of them
  // pull (a random sample, the same for every such level and growing with
  // E), each stiffened by #targets / #sample so that the data's total
  // stiffness stays what it is. A coarse surface is set by far fewer points
  // than a dense scan has, and each spring costs a closest-point search at
  // every evaluation. lengths() and signedLengths() are then the sample's.
  // 0 (the default): every target pulls at every level.
  void setSamplePerElement(double perElement);

 private:
  void attach(const MatrixX3& controlPoints);

  MatrixX3 allTargets_;
  Eigen::VectorXd allStiffness_;
  MatrixX3 targets_;  // the springs of this level: all or the sample
  Eigen::VectorXd stiffness_;
  double samplePerElement_ = 0;
  std::vector<Eigen::Index> sampleOrder_;  // a fixed random order of the targets
  Attach attach_;
  const LimitSurface* surface_ = nullptr;
  std::unique_ptr<ClosestPointLocator> locator_;
  std::vector<Spring> springs_;       // at the last evaluation
  std::vector<ElementPoint> tracked_;  // attachments at the last accepted state
  MatrixX3 positions_;                 // the surface at the attachments (NearestEachStep)
  MatrixX3 normals_;                   // and its unit normals there
  Eigen::VectorXd lengths_;
  // Per spring at the last evaluation: its attachment's position stencil on
  // a special element, empty on a normal one (NearestEachStep).
  std::vector<Eigen::RowVectorXd> stencils_;
  double deadZone_ = 0;
};

// A pressure (N/mm^2) along the limit normal; positive inflates an outward-oriented surface.
class InflationForceModel final : public ForceModel {
 public:
  explicit InflationForceModel(double pressure);
  void beginLevel(const LimitSurface& surface, const SurfaceQuadrature& quadrature,
                  const MatrixX3& controlPoints) override;
  MatrixX3 generalizedForce(const MatrixX3& controlPoints, double& potential) override;

 private:
  double pressure_;
  const SurfaceQuadrature* quadrature_ = nullptr;
};

// An external force-density field (N/mm^2), e.g. image forces, and
// optionally a pressure field acting with it (evaluated at the same points,
// Forces.h's fieldForces). Neither is owned.
class FieldForceModel final : public ForceModel {
 public:
  explicit FieldForceModel(const ForceField& field, const PressureField* pressure = nullptr)
      : field_(field), pressure_(pressure) {}
  void beginLevel(const LimitSurface& surface, const SurfaceQuadrature& quadrature,
                  const MatrixX3& controlPoints) override;
  MatrixX3 generalizedForce(const MatrixX3& controlPoints, double& potential) override;
  // fieldStiffness with the field's slopeBound (plus the pressure's): a
  // field that reverses across an edge is a stiff explicit force, which the
  // papers' schemes would let oscillate about the edge instead of settling on it.
  SparseMatrix stabilizingStiffness(const MatrixX3& controlPoints) override;

 private:
  const ForceField& field_;
  const PressureField* pressure_ = nullptr;
  const SurfaceQuadrature* quadrature_ = nullptr;
};

}  // namespace dynsub
