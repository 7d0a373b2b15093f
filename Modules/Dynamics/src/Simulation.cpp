#include "dynsub/Simulation.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <deque>
#include <future>
#include <limits>
#include <memory>
#include <optional>
#include <sstream>
#include <string>

#include <Eigen/SparseCholesky>

#include "dynsub/ParallelFor.h"
#include "dynsub/ApplyOperator.h"
#include "dynsub/CatmullClark.h"
#include "dynsub/Error.h"
#include "dynsub/LimitSurface.h"
#include "dynsub/StaticSolver.h"

namespace dynsub {

namespace {

double modelSize(const MatrixX3& points) {
  return (points.colwise().maxCoeff() - points.colwise().minCoeff()).norm();
}

// sum over x, y, z of a^T A a.
double quadraticForm(const SymmetricMatrix& a, const MatrixX3& x) {
  return (x.array() * applyOperator(a, x).array()).sum();
}

// |energy - last| relative to the larger of the two, or to `floor` where
// both are smaller (LevelModel::energyFloor).
double relativeChange(double energy, double last, double floor) {
  return std::abs(energy - last) / std::max({std::abs(energy), std::abs(last), floor, 1e-300});
}

// Everything a level is built on: the surface of its control mesh and the
// matrices and quadrature over it (rebuilt only when the mesh is refined; the
// matrices also when the level is relaxed).
struct LevelModel {
  int level = 0;
  // Shared so that the last level's can be handed out with the result.
  std::shared_ptr<const LimitSurface> surface;
  PhysicalMatrices matrices;
  SurfaceQuadrature quadrature;
  MatrixX3 start;
  double size = 0;         // bounding-box diagonal of the control points, mm
  double elementSize = 0;  // in elements of the initial model
  double elasticity = 1;   // the factor on the matrices' tension and rigidity
  // The mesh's points as blends of the free points the level moves
  // (RefineRegion; #mesh vertices by #free), or empty: every point free.
  // The surface, the matrices and the states are over the free points.
  SparseMatrix freeBasis{};
  // 1/2 r^T K r of the rest shape r (SimulationOptions::restShape; 0 without
  // one): the size of the terms that cancel in the energy 1/2 (p - r)^T K
  // (p - r) as it is summed. Near the rest shape the energy is rounding of
  // that size, whose changes are no rise and no divergence, and are measured
  // against energyFloor rather than against the energy.
  double restEnergy = 0;
  double energyFloor = 0;  // 1e-9 restEnergy: well above the sum's rounding
};

// The mesh's points at free points `points` (LevelModel::freeBasis).
MatrixX3 meshPoints(const SparseMatrix& freeBasis, const MatrixX3& points) {
  return freeBasis.size() == 0 ? points : MatrixX3(freeBasis * points);
}

// Sets the model's start, its free points.
void setStart(LevelModel& model, const MatrixX3& points) {
  model.start = points;
  model.size = modelSize(meshPoints(model.freeBasis, model.start));
  if (!(model.size > 0.0)) throw Error("the control mesh has no extent");
}

// The model's mass, damping and stiffness, with tension and rigidity times
// `elasticity` (elasticityPerLevel^g at level g, once more per relaxation).
// Swapped in, not assigned: Eigen 3.4's sparse matrices have no move, so
// assigning the results would copy every table.
void assembleMatrices(LevelModel& model, double elasticity, const SimulationOptions& options) {
  AssemblyOptions assembly = options.assembly;
  assembly.elementSize = model.elementSize;
  PhysicalMatrices built =
      assemblePhysicalMatrices(*model.surface, options.material.withElasticity(elasticity), assembly);
  model.matrices.mass.swap(built.mass);
  model.matrices.damping.swap(built.damping);
  model.matrices.stiffness.swap(built.stiffness);
  model.elasticity = elasticity;
}

// initialIsolation < 0: `mesh` is the initial model, and sets it. `relaxed`:
// the relaxations the level has had already (LevelOrigin). freeBasis and
// points: LevelModel's, and the free points the level starts from.
LevelModel buildLevel(const ControlMesh& mesh, int level, int relaxed, int& initialIsolation,
                      const SimulationOptions& options, const SparseMatrix& freeBasis, const MatrixX3& points) {
  LevelModel model{level, std::make_shared<const LimitSurface>(mesh, freeBasis), {}, {}, {}, 0.0};
  model.freeBasis = freeBasis;
  if (initialIsolation < 0) initialIsolation = model.surface->isolationLevels();
  // Element sides are measured in elements of the initial model: a base mesh
  // that is `b` global refinements past the initial one has side 2^-b.
  model.elementSize = std::ldexp(1.0, initialIsolation - (level + model.surface->isolationLevels()));
  // The matrices and the quadrature are independent (the surface's
  // tables are safe to fill from two threads), and each is a sizeable share
  // of a level, so they are built side by side.
  bothAtOnce([&] { assembleMatrices(model, std::pow(options.elasticityPerLevel, level + relaxed), options); },
             [&] {
               SurfaceQuadrature built =
                   makeSurfaceQuadrature(*model.surface, options.quadraturePoints, model.elementSize);
               model.quadrature.points.swap(built.points);
               model.quadrature.weights.swap(built.weights);
               model.quadrature.J.swap(built.J);
               model.quadrature.Ju.swap(built.Ju);
               model.quadrature.Jv.swap(built.Jv);
             });
  setStart(model, points);
  return model;
}

// f_p at `points`; adds the forces' potential energy to `potential`.
MatrixX3 totalForce(const std::vector<ForceModel*>& forces, const MatrixX3& points, double& potential) {
  MatrixX3 force = MatrixX3::Zero(points.rows(), 3);
  for (ForceModel* f : forces) force += f->generalizedForce(points, potential);
  return force;
}

void acceptState(const std::vector<ForceModel*>& forces) {
  for (ForceModel* f : forces) f->acceptState();
}

// The elasticity's pull toward a rest shape r (SimulationOptions::restShape):
// the energy 1/2 (p - r)^T K (p - r) is 1/2 p^T K p less (K r)^T p, plus a
// constant, so r adds the constant force K r.
class RestShapeForce final : public ForceModel {
 public:
  // K and r of a level, over its free points.
  void set(const SymmetricMatrix& stiffness, const MatrixX3& rest) {
    force_ = stiffness * rest;
    restEnergy_ = 0.5 * (force_.array() * rest.array()).sum();
  }
  void beginLevel(const LimitSurface&, const SurfaceQuadrature&, const MatrixX3&) override {}
  MatrixX3 generalizedForce(const MatrixX3& controlPoints, double& potential) override {
    potential += restEnergy_ - (force_.array() * controlPoints.array()).sum();
    return force_;
  }
  bool hasPotential() const override { return true; }
  double restEnergy() const { return restEnergy_; }

 private:
  MatrixX3 force_;
  double restEnergy_ = 0;
};

// The equilibrium rule of Simulation.h over a sliding window of steps.
class EquilibriumWindow {
 public:
  EquilibriumWindow(const EquilibriumOptions& options, int window) : options_(options), window_(window) {}
  void clear() { recent_.clear(); }
  // Whether a step (relative energy change, largest move / model size) is still.
  bool still(double change, double motion) const {
    return change <= options_.energyTolerance && motion <= options_.motionTolerance;
  }
  // Records a step; true when the last `window` steps were all still.
  bool settled(double change, double motion) {
    recent_.emplace_back(change, motion);
    if (static_cast<int>(recent_.size()) > window_) recent_.pop_front();
    if (static_cast<int>(recent_.size()) < window_) return false;
    return std::all_of(recent_.begin(), recent_.end(),
                       [&](const std::pair<double, double>& step) { return still(step.first, step.second); });
  }

 private:
  const EquilibriumOptions& options_;
  int window_;
  std::deque<std::pair<double, double>> recent_;
};

// The limit surface at the quadrature points of one state: positions and
// unit normals (zero where the normal degenerates: a collapsed element).
struct SurfaceFrame {
  MatrixX3 positions, normals;
};

SurfaceFrame surfaceFrame(const SurfaceQuadrature& quadrature, const MatrixX3& points) {
  SurfaceFrame frame;
  MatrixX3 su, sv;
  applyOperators(quadrature.J, quadrature.Ju, quadrature.Jv, points, frame.positions, su, sv);  // one pass
  frame.normals.resize(su.rows(), 3);
  for (Eigen::Index i = 0; i < su.rows(); ++i) {
    const Eigen::Vector3d n = su.row(i).transpose().cross(sv.row(i).transpose());
    const double length = n.norm();
    frame.normals.row(i) = length > 0.0 ? Eigen::RowVector3d(n.transpose() / length) : Eigen::RowVector3d::Zero();
  }
  return frame;
}

// How far a step from `from` to `to` moved the limit surface across itself:
// the largest |n . (s(to) - s(from))| over the quadrature points, n the unit
// normal at `from`. Steps also slide the parametrization along the surface,
// which changes no shape, for hundreds of steps after the shape has settled
// (Simulation.h), so control-point motion would keep it "moving".
// Each state's frame is computed once and compared with the next
// state's: one pass over the operators per state, not three per step (J on
// the move, J_u and J_v at `from`).
double shapeMotion(const SurfaceFrame& from, const SurfaceFrame& to) {
  double largest = 0.0;
  for (Eigen::Index i = 0; i < from.positions.rows(); ++i) {
    const Eigen::RowVector3d moved = to.positions.row(i) - from.positions.row(i);
    // A degenerate normal counts the whole move.
    const double across = from.normals.row(i).isZero(0.0) ? moved.norm() : std::abs(from.normals.row(i).dot(moved));
    largest = std::max(largest, across);
  }
  return largest;
}

// The equilibrium rule `coarseLevelFactor` times looser (Simulation.h).
EquilibriumOptions loosened(const EquilibriumOptions& options) {
  EquilibriumOptions loose = options;
  loose.energyTolerance *= options.coarseLevelFactor;
  loose.motionTolerance *= options.coarseLevelFactor;
  return loose;
}

// The shape's motion over a level's steps (shapeMotion / model size),
// measured only for steps whose energy change is within the tolerance in
// force: the others are not still whatever their motion, and most steps are
// such (they get infinity). Each state's frame is computed at most once.
class StepShapeMotion {
 public:
  explicit StepShapeMotion(const LevelModel& model) : model_(model) {}
  // The step from `previous` to `current`, whose relative energy change is `change`.
  double measure(const MatrixX3& previous, const MatrixX3& current, double change, double tolerance) {
    if (!(change <= tolerance)) return std::numeric_limits<double>::infinity();
    if (!previousFrame_) previousFrame_ = surfaceFrame(model_.quadrature, previous);
    if (!frame_) frame_ = surfaceFrame(model_.quadrature, current);
    return shapeMotion(*previousFrame_, *frame_) / model_.size;
  }
  // The state moved on: its frame becomes the previous one.
  void advance() {
    previousFrame_ = std::move(frame_);
    frame_.reset();
  }

 private:
  const LevelModel& model_;
  std::optional<SurfaceFrame> previousFrame_, frame_;  // at `previous` and `current`, once computed
};

// Coarse: a level below the maximum settled to the looser rule and its fit
// was not accepted (EquilibriumOptions::coarseLevelFactor); Accepted: it was,
// and the simulation stops there (FitVerdict::Stop); Met: the fit was
// accepted after a step (FitAsk::Step), and the simulation stops there.
enum class LevelEnd { Equilibrium, Coarse, Accepted, Met, StepLimit, Diverged };

// A level asked at the looser rule: how it ends, if it does.
std::optional<LevelEnd> coarseEnd(FitVerdict verdict) {
  if (verdict == FitVerdict::Refine || verdict == FitVerdict::Relax) return LevelEnd::Coarse;
  if (verdict == FitVerdict::Stop) return LevelEnd::Accepted;
  return std::nullopt;
}

// The papers' time stepping (Integrator.h) from model.start; `points` ends at
// the last state reached.
LevelEnd runTimeSteps(const LevelModel& model, const std::vector<ForceModel*>& forces, const std::vector<int>& fixed,
                      const SimulationOptions& options, const AcceptFit& accept, bool askLoose, double& timeStep,
                      double regrowCeiling, const ProgressCallback& progress, MatrixX3& points, LevelSummary& summary) {
  IntegratorOptions integratorOptions = options.integrator;
  integratorOptions.timeStep = timeStep;
  // The stabilizing stiffness of the forces at `at` (Integrator.h).
  auto stabilizingAt = [&](const MatrixX3& at) {
    SymmetricMatrix stabilizing(at.rows(), at.rows());
    for (ForceModel* f : forces) {
      const SparseMatrix s = f->stabilizingStiffness(at);
      if (s.size() > 0) stabilizing += SymmetricMatrix(s);
    }
    return stabilizing;
  };
  Integrator integrator(model.matrices, stabilizingAt(model.start), fixed, integratorOptions);
  EquilibriumWindow window(options.equilibrium, options.equilibrium.window);
  // With `askLoose`, the level is asked at the first state that meets the
  // looser rule whether its fit is accepted, as in runStaticSteps.
  const EquilibriumOptions loose = loosened(options.equilibrium);
  EquilibriumWindow looseWindow(loose, options.equilibrium.window);
  bool asked = !askLoose;
  MatrixX3 previous = model.start;
  points = model.start;
  StepShapeMotion stepMotion(model);
  double lastEnergy = std::numeric_limits<double>::quiet_NaN();
  double firstEnergy = 0.0;
  int rises = 0;
  int falling = 0;  // steps in a row whose energy fell
  double energyTwoBefore = std::numeric_limits<double>::quiet_NaN();
  for (int step = 1; step <= options.equilibrium.maxSteps; ++step) {
    double potential = 0.0;
    const MatrixX3 force = totalForce(forces, points, potential);
    acceptState(forces);
    const MatrixX3 velocity = (points - previous) / timeStep;
    const double energy = 0.5 * quadraticForm(model.matrices.mass, velocity) +
                          0.5 * quadraticForm(model.matrices.stiffness, points) + potential;
    if (step == 1) firstEnergy = std::max(std::abs(energy), model.restEnergy);
    if (!std::isfinite(energy) || std::abs(energy) > 1e3 * std::max(firstEnergy, 1e-300)) return LevelEnd::Diverged;
    if (step > 1) {
      // The forces were just evaluated at `points`: a fit met there ends here.
      if (accept && accept(*model.surface, points, FitAsk::Step) == FitVerdict::Stop) {
        summary.energy = energy;
        return LevelEnd::Met;
      }
      const double change = relativeChange(energy, lastEnergy, model.energyFloor);
      const double shape = stepMotion.measure(
          previous, points, change, asked ? options.equilibrium.energyTolerance : loose.energyTolerance);
      const bool still = window.settled(change, shape);
      const bool looselyStill = !asked && looseWindow.settled(change, shape);
      // The motion is dissipative and re-attaching springs only lowers their
      // energy, so an energy that keeps rising means the forces' stiffness
      // has drifted from the one the integrator was built with. Changes
      // within the equilibrium tolerance are not rises: near an equilibrium
      // they are noise (and forces without a potential, like image forces,
      // make the counted energy wander by that much).
      rises = change > options.equilibrium.energyTolerance && energy > lastEnergy ? rises + 1 : 0;
      if (rises >= 3) {
        integrator.restabilize(model.matrices, stabilizingAt(points));
        ++summary.stabilizerUpdates;
        rises = 0;
        window.clear();
        looseWindow.clear();
      } else if (still) {
        summary.energy = energy;
        return LevelEnd::Equilibrium;
      } else if (looselyStill) {
        asked = true;
        if (const std::optional<LevelEnd> end = coarseEnd(accept(*model.surface, points, FitAsk::LooseRule))) {
          summary.energy = energy;
          return *end;
        }
      }
    }
    // A halved step grows back once the energy has fallen for a while
    // (Simulation.h), compared with two steps before: the first-order step
    // spans two (p(t - dt) to p(t + dt)), and the kinetic energy of odd and
    // even steps can alternate on the way down.
    falling = step > 2 && energy < energyTwoBefore ? falling + 1 : 0;
    energyTwoBefore = lastEnergy;
    if (options.timeStepRegrowth > 0 && falling >= options.timeStepRegrowth && timeStep < regrowCeiling) {
      // The next step takes `previous`, one old step back, for one new
      // step back; the steps after it correct that, and the equilibrium does
      // not depend on it. The stabilizer is frozen anew here too (not counted
      // in stabilizerUpdates, which counts the energy's rises).
      timeStep = std::min(2.0 * timeStep, regrowCeiling);
      integratorOptions.timeStep = timeStep;
      integrator = Integrator(model.matrices, stabilizingAt(points), fixed, integratorOptions);
      falling = 0;
      window.clear();
      looseWindow.clear();
    }
    lastEnergy = energy;
    summary.energy = energy;

    MatrixX3 next = integrator.step(previous, points, force);
    summary.solverIterations += integrator.lastIterations();
    const double motion = (next - points).rowwise().norm().maxCoeff();
    if (!next.allFinite() || motion > model.size) return LevelEnd::Diverged;
    previous = std::move(points);
    points = std::move(next);
    stepMotion.advance();
    summary.steps = step;
    if (progress) progress(Progress{model.level, step, energy, motion, model.surface.get(), &points});
  }
  return LevelEnd::StepLimit;
}

// Newton steps on K p = f_p (StaticSolver.h). When every force has a
// potential, the total energy 1/2 p^T K p + potential is what the
// equilibrium minimizes, and a step that does not lower it is shortened (up
// to 20 times, by a factor of 2-10 each; a direction that lowers nothing even
// then means the state is at the minimum to rounding). Otherwise only a step
// moving a point farther than the model's size is halved.
// With `askLoose` (a level below the maximum), the level is asked at the
// first state that meets the looser rule whether its fit is accepted; if not,
// it ends there, and if so it goes on, unchanged, to the full rule. With
// `accept`, it is also asked after every step whether the fit is met there.
LevelEnd runStaticSteps(const LevelModel& model, const std::vector<ForceModel*>& forces, const std::vector<int>& fixed,
                        const SimulationOptions& options, const AcceptFit& accept, bool askLoose,
                        const ProgressCallback& progress, MatrixX3& points, LevelSummary& summary) {
  bool lineSearch = true;
  for (const ForceModel* f : forces) lineSearch = lineSearch && f->hasPotential();
  StaticSolver solver(*model.surface, model.matrices.stiffness, fixed);
  auto finish = [&](LevelEnd end) {
    summary.stabilizerUpdates = solver.regularizations();
    return end;
  };
  // A static step that moves nothing is conclusive by itself (there is no
  // velocity to carry the state on), so two still steps in a row suffice.
  EquilibriumWindow window(options.equilibrium, std::min(options.equilibrium.window, 2));
  const EquilibriumOptions loose = loosened(options.equilibrium);
  EquilibriumWindow looseWindow(loose, std::min(options.equilibrium.window, 2));
  bool asked = !askLoose;
  points = model.start;
  double potential = 0.0;
  MatrixX3 force = totalForce(forces, points, potential);
  acceptState(forces);
  double energy = 0.5 * quadraticForm(model.matrices.stiffness, points) + potential;
  summary.energy = energy;
  if (!std::isfinite(energy)) return LevelEnd::Diverged;
  MatrixX3 previous;
  StepShapeMotion stepMotion(model);
  // The length the last Newton direction was accepted at.
  double lastLength = 1.0;
  // Whether the last step was still by the full rule. (Not the coarse one:
  // the path of a level accepted at the looser rule must not depend on it.)
  bool lastStill = false;
  for (int step = 1; step <= options.equilibrium.maxSteps; ++step) {
    const MatrixX3 residual = force - model.matrices.stiffness * points;
    MatrixX3 trial, trialForce;
    double trialEnergy = energy;
    bool accepted = false, evaluated = false;
    // The Newton direction first; where it lowers nothing, the isotropic one.
    for (const bool isotropic : {false, true}) {
      if (isotropic && !lineSearch) break;
      const MatrixX3 direction = solver.direction(forces, points, residual, isotropic);
      if (!direction.allFinite()) return LevelEnd::Diverged;
      // The energy's slope along the direction: its gradient is K p - f_p.
      const double slope = -(residual.array() * direction.array()).sum();
      // A Newton direction first tries the length the last one was
      // accepted at: near an equilibrium the full step can raise the energy
      // step after step while a fraction of it is accepted, and the best
      // length changes slowly. After a still step the next starts at 1
      // again: a step started short may look still only because it was
      // short, and a level must not end on two such steps. On the tuning
      // clouds this takes fewer force evaluations than starting at 1 or at a
      // multiple of the last length.
      double length = isotropic || !lineSearch || lastStill ? 1.0 : lastLength;
      const double largestMove = direction.rowwise().norm().maxCoeff();
      for (int shortening = 0; shortening <= 20 && !accepted; ++shortening) {
        const double tried = length;  // this trial's length; `length` becomes the next one
        length *= 0.5;
        if (largestMove * tried > model.size) continue;
        trial = points + tried * direction;
        double trialPotential = 0.0;
        trialForce = totalForce(forces, trial, trialPotential);
        trialEnergy = 0.5 * quadraticForm(model.matrices.stiffness, trial) + trialPotential;
        if (!std::isfinite(trialEnergy)) continue;
        evaluated = true;
        // Rounding of the energy's sum must not count as a rise.
        accepted = !lineSearch || trialEnergy <= energy + 1e-12 * (std::abs(energy) + model.restEnergy);
        if (accepted && !isotropic) lastLength = tried;
        // The next length is the lowest point of the parabola through the
        // energy here, its slope here and the energy at the rejected length,
        // kept within 0.1-0.5 of that length (safeguarded backtracking).
        // Steps are often accepted at 1/8-1/16 of the Newton step, and
        // every trial is a whole closest-point search: plain halving would
        // take several trials to get there, the parabola's minimum fewer.
        const double rise = trialEnergy - energy - slope * tried;
        if (slope < 0.0 && rise > 0.0) {
          length = std::clamp(-slope * tried * tried / (2.0 * rise), 0.1 * tried, 0.5 * tried);
        }
      }
      if (accepted) break;
    }
    if (!accepted) {
      // Neither direction lowers the energy: a minimum to rounding. (The
      // forces were last evaluated at a rejected trial, but they track from
      // `points`, the last accepted state, so nothing needs restoring.)
      return finish(lineSearch && evaluated ? LevelEnd::Equilibrium : LevelEnd::Diverged);
    }
    const double motion = (trial - points).rowwise().norm().maxCoeff();
    const double change = relativeChange(trialEnergy, energy, model.energyFloor);
    acceptState(forces);
    previous = std::move(points);
    points = std::move(trial);
    stepMotion.advance();
    force = std::move(trialForce);
    energy = trialEnergy;
    summary.energy = energy;
    summary.steps = step;
    if (progress) progress(Progress{model.level, step, energy, motion, model.surface.get(), &points});
    // The accepted trial was the forces' last evaluation: a fit met there ends here.
    if (accept && accept(*model.surface, points, FitAsk::Step) == FitVerdict::Stop) return finish(LevelEnd::Met);
    const double shape = stepMotion.measure(previous, points, change,
                                             asked ? options.equilibrium.energyTolerance : loose.energyTolerance);
    if (window.settled(change, shape)) return finish(LevelEnd::Equilibrium);
    lastStill = window.still(change, shape);
    if (!asked && looseWindow.settled(change, shape)) {
      asked = true;
      if (const std::optional<LevelEnd> end = coarseEnd(accept(*model.surface, points, FitAsk::LooseRule))) {
        return finish(*end);
      }
    }
  }
  return finish(LevelEnd::StepLimit);
}

// |f_p - K p| / max(|f_p|, |K p|) at `points` (Frobenius norms): 0 exactly at
// the papers' equilibrium.
double equilibriumResidual(const LevelModel& model, const std::vector<ForceModel*>& forces, const MatrixX3& points,
                           const std::vector<int>& fixed) {
  double potential = 0.0;
  MatrixX3 force = totalForce(forces, points, potential);
  MatrixX3 elastic = model.matrices.stiffness * points;
  for (int v : fixed) {  // fixed vertices are held by their supports
    force.row(v).setZero();
    elastic.row(v).setZero();
  }
  const double scale = std::max({force.norm(), elastic.norm(), 1e-300});
  return (force - elastic).norm() / scale;
}

// One level from model.start to its end (an equilibrium rule, the fit met, or
// the step limit); a divergence restarts it with half the time step.
MatrixX3 runLevel(const LevelModel& model, const std::vector<ForceModel*>& forces, const std::vector<int>& fixed,
                  const SimulationOptions& options, const AcceptFit& accept, bool askLoose, double& timeStep,
                  const ProgressCallback& progress, LevelSummary& summary, LevelEnd& end) {
  MatrixX3 points;
  // The largest step a halved one may grow back to: the step asked for, then
  // half of any regrown step that diverged.
  double regrowCeiling = std::max(timeStep, options.integrator.timeStep);
  for (int halvings = 0;; ++halvings) {
    if (halvings > options.maxTimeStepHalvings) {
      std::ostringstream message;
      message << "the simulation diverged at level " << model.level << " even with time step " << timeStep * 2.0
              << " s (try a smaller --time-step or softer forces)";
      throw Error(message.str());
    }
    const double startStep = timeStep;
    for (ForceModel* f : forces) f->beginLevel(*model.surface, model.quadrature, model.start);
    summary.steps = 0;
    summary.solverIterations = 0;
    summary.stabilizerUpdates = 0;
    if (options.integrator.scheme == IntegrationScheme::Static) {
      end = runStaticSteps(model, forces, fixed, options, accept, askLoose, progress, points, summary);
      if (end == LevelEnd::Diverged) {
        throw Error("the static scheme found no finite step at level " + std::to_string(model.level) +
                    " (try --scheme first-order or softer forces)");
      }
    } else {
      end = runTimeSteps(model, forces, fixed, options, accept, askLoose, timeStep, regrowCeiling, progress, points,
                         summary);
    }
    if (end != LevelEnd::Diverged) {
      summary.converged = end != LevelEnd::StepLimit;
      summary.coarse = end == LevelEnd::Coarse || end == LevelEnd::Accepted;
      summary.met = end == LevelEnd::Met;
      summary.timeStep = timeStep;
      return points;
    }
    ++summary.divergences;
    if (timeStep > startStep) {
      // Diverged at a regrown step: start again where the level started, and
      // grow no further than below the step that diverged.
      regrowCeiling = 0.5 * timeStep;
      timeStep = startStep;
      --halvings;  // the ceiling halves each time, so this ends
    } else {
      timeStep *= 0.5;
    }
  }
}

}  // namespace

bool takesRefineRegion(const SimulationOptions& options) {
  return options.integrator.scheme == IntegrationScheme::Static;
}

void checkSimulationOptions(const SimulationOptions& o) {
  checkMaterial(o.material);
  const EquilibriumOptions& e = o.equilibrium;
  if (!(e.energyTolerance > 0.0) || !(e.motionTolerance > 0.0) || e.window < 1 || e.maxSteps < 1) {
    throw Error("equilibrium tolerances must be > 0, the window and the step limit >= 1");
  }
  if (!(e.coarseLevelFactor >= 1.0 && std::isfinite(e.coarseLevelFactor))) {
    throw Error("the coarse levels' tolerance factor must be finite and >= 1");
  }
  if (o.maxLevel < 0 || o.maxLevel > 6) throw Error("the maximum level must be in 0..6, got " + std::to_string(o.maxLevel));
  if (o.origin.level < 0 || o.origin.level > o.maxLevel || o.origin.isolation < -1 ||
      (o.origin.level > 0 && o.origin.isolation < 0) || o.origin.relaxed < 0) {
    throw Error("the initial mesh's level must be in 0..maximum level (" + std::to_string(o.maxLevel) + "), got " +
                std::to_string(o.origin.level) + " (isolation " + std::to_string(o.origin.isolation) +
                ", relaxations " + std::to_string(o.origin.relaxed) + ")");
  }
  if (o.maxTimeStepHalvings < 0) throw Error("time-step halvings must be >= 0");
  if (o.timeStepRegrowth < 0) throw Error("the time step's regrowth must be >= 0 steps (0: none)");
  if (o.relaxations < 0) throw Error("relaxations per level must be >= 0, got " + std::to_string(o.relaxations));
  if (!(o.elasticityPerLevel > 0.0 && o.elasticityPerLevel <= 1.0)) {
    throw Error("the elasticity factor per level must be in (0, 1], got " + std::to_string(o.elasticityPerLevel));
  }
  if (!(std::isfinite(o.integrator.timeStep) && o.integrator.timeStep > 0.0)) {
    throw Error("time step must be positive, got " + std::to_string(o.integrator.timeStep));
  }
  if (o.integrator.scheme == IntegrationScheme::FirstOrder && !(o.material.damping > 0.0)) {
    throw Error("first-order integration needs a damping > 0");
  }
  if (o.integrator.scheme == IntegrationScheme::SecondOrder && !(o.material.mass > 0.0)) {
    throw Error("second-order integration needs a mass > 0");
  }
}

namespace {

// Whether the columns of `m` are independent on the rows not in `rows`: their
// Gram matrix there factors with pivots above 1e-12 of the largest.
bool independentOffRows(const SparseMatrix& m, const std::vector<int>& rows) {
  std::vector<bool> skipped(m.rows(), false);
  for (int r : rows) skipped[r] = true;
  SparseMatrix off = m;
  off.prune([&](const Eigen::Index& row, const Eigen::Index&, const double&) { return !skipped[row]; });
  const SymmetricMatrix gram = SymmetricMatrix(off.transpose() * off);
  const Eigen::SimplicialLDLT<SymmetricMatrix> factor(gram);
  if (factor.info() != Eigen::Success) return false;
  const Eigen::VectorXd pivots = factor.vectorD();
  return pivots.minCoeff() > 1e-12 * pivots.cwiseAbs().maxCoeff();
}

// The rows of `m` that have nonzeros, all in the columns marked in `columns`.
std::vector<bool> rowsWithin(const SparseMatrix& m, const std::vector<bool>& columns) {
  std::vector<bool> within(m.rows(), false);
  for (Eigen::Index row = 0; row < m.outerSize(); ++row) {
    bool any = false, all = true;
    for (SparseMatrix::InnerIterator it(m, row); it; ++it) {
      if (it.value() == 0.0) continue;
      any = true;
      all = all && columns[it.col()];
    }
    within[row] = any && all;
  }
  return within;
}

// The points of the mesh refined by `subdivision` that stay where they are
// (the fixed control vertices of simulate, Simulation.h): the held points of
// the coarse mesh, which keep their numbers, and every refined point that the
// held points alone determine (an open mesh's held boundary: its refined
// vertex and edge points).
std::vector<bool> heldRefinedRows(const SparseMatrix& subdivision, const std::vector<bool>& held) {
  std::vector<bool> rows = rowsWithin(subdivision, held);
  for (size_t v = 0; v < held.size(); ++v) rows[v] = rows[v] || held[v];
  return rows;
}

// `points` followed by zero rows, up to `rows` in all: free points carried
// into a refined basis, whose new columns are offsets (refinedBasis).
MatrixX3 withNewOffsets(const MatrixX3& points, Eigen::Index rows) {
  MatrixX3 padded = MatrixX3::Zero(rows, 3);
  padded.topRows(points.rows()) = points;
  return padded;
}

// The indices marked in `mask`.
std::vector<int> indicesOf(const std::vector<bool>& mask) {
  std::vector<int> indices;
  for (int i = 0; i < static_cast<int>(mask.size()); ++i) {
    if (mask[i]) indices.push_back(i);
  }
  return indices;
}

// The free basis after `coarse` is refined (RefineRegion): the free points
// before, carried by the subdivision matrix A (A T, or A itself where every
// point was free), then one new free point per edge point and face point of
// the faces named. The new points' columns are unit columns on their own
// rows, so T's columns are independent when the carried columns are on the
// other rows; almost always they are (the vertex points alone usually
// determine them), but A can have a null vector (on a cube of 8 vertices of
// valence 3, alternating signs give zero face, edge and vertex points).
// There a direction of the free points would move nothing and the Newton
// systems T^T (K + H) T would be singular, so the step is refined globally
// instead. Empty (every point free) when the refinement is global.
// heldFreePoints: the free points that do not move; heldMeshPoints: the
// refined mesh's points that must not move (heldRefinedRows). An edge or face
// point that the held points alone determine gets no free point of its own,
// so that it stays; a held mesh point that a free point would move (an
// interior vertex held alone: its vertex point blends its free neighbours)
// cannot stay under a basis, and the step is refined globally instead.
SparseMatrix refinedBasis(const Topology& coarse, const SparseMatrix& subdivision, const SparseMatrix& basis,
                          const std::vector<int>& faces, const std::vector<bool>& heldFreePoints,
                          const std::vector<bool>& heldMeshPoints) {
  std::vector<bool> refined(coarse.faceCount(), false);
  for (int f : faces) {
    if (f < 0 || f >= coarse.faceCount()) throw Error("internal: a face to refine does not exist");
    refined[f] = true;
  }
  const bool everyFace = std::find(refined.begin(), refined.end(), false) == refined.end();
  if (basis.size() == 0 && everyFace) return SparseMatrix();
  const int vertices = coarse.vertexCount(), edges = coarse.edgeCount();
  std::vector<bool> freeEdge(edges, false);
  for (int f = 0; f < coarse.faceCount(); ++f) {
    for (int k = 0; refined[f] && k < coarse.faceSize(f); ++k) freeEdge[coarse.faceEdge(f, k)] = true;
  }
  const SparseMatrix carried = basis.size() == 0 ? subdivision : SparseMatrix(subdivision * basis);
  const std::vector<bool> determined = rowsWithin(carried, heldFreePoints);
  for (int row = 0; row < static_cast<int>(heldMeshPoints.size()); ++row) {
    if (heldMeshPoints[row] && !determined[row]) return SparseMatrix();
  }
  std::vector<int> newPoints;
  for (int e = 0; e < edges; ++e) {
    if (freeEdge[e] && !determined[vertices + e]) newPoints.push_back(vertices + e);
  }
  for (int f = 0; f < coarse.faceCount(); ++f) {
    if (refined[f] && !determined[vertices + edges + f]) newPoints.push_back(vertices + edges + f);
  }
  if (!independentOffRows(carried, newPoints)) return SparseMatrix();
  std::vector<Triplet> entries;
  entries.reserve(static_cast<size_t>(carried.nonZeros()) + newPoints.size());
  for (Eigen::Index row = 0; row < carried.outerSize(); ++row) {
    for (SparseMatrix::InnerIterator it(carried, row); it; ++it) entries.emplace_back(row, it.col(), it.value());
  }
  for (size_t j = 0; j < newPoints.size(); ++j) {
    entries.emplace_back(newPoints[j], static_cast<int>(carried.cols() + j), 1.0);
  }
  SparseMatrix result(carried.rows(), carried.cols() + static_cast<Eigen::Index>(newPoints.size()));
  result.setFromTriplets(entries.begin(), entries.end());
  return result;
}

}  // namespace

std::vector<int> refinedFixedVertices(const SparseMatrix& subdivision, const std::vector<int>& fixed) {
  std::vector<bool> held(subdivision.cols(), false);
  for (int v : fixed) {
    if (v < 0 || v >= subdivision.cols()) throw Error("internal: a fixed control vertex does not exist");
    held[v] = true;
  }
  return indicesOf(heldRefinedRows(subdivision, held));
}

std::vector<int> grownFaces(const Topology& mesh, const std::vector<int>& faces, int rings) {
  std::vector<bool> chosen(mesh.faceCount(), faces.empty());
  for (int f : faces) chosen[f] = true;
  for (int ring = 0; ring < rings && !faces.empty(); ++ring) {
    std::vector<bool> grown = chosen;
    for (int f = 0; f < mesh.faceCount(); ++f) {
      if (!chosen[f]) continue;
      for (int v : mesh.face(f)) {
        for (int g : mesh.vertexFaces(v)) grown[g] = true;
      }
    }
    chosen = std::move(grown);
  }
  std::vector<int> result;
  for (int f = 0; f < mesh.faceCount(); ++f) {
    if (chosen[f]) result.push_back(f);
  }
  return result;
}

SimulationResult simulate(const ControlMesh& initial, const std::vector<ForceModel*>& forces,
                          const std::vector<int>& fixed, const SimulationOptions& options, const AcceptFit& accept,
                          const ProgressCallback& progress, const RefineRegion& region) {
  checkSimulationOptions(options);
  for (int v : fixed) {
    if (v < 0 || v >= initial.vertexCount()) {
      throw Error("fixed control vertex " + std::to_string(v) + " does not exist (the mesh has " +
                  std::to_string(initial.vertexCount()) + ")");
    }
  }
  const bool local = region && takesRefineRegion(options);
  SimulationResult result;
  // The mesh's points that do not move, and the free points that do not
  // (the same while every point is free; the carried free points keep their
  // numbers under a basis).
  std::vector<bool> heldMeshPoints(initial.vertexCount(), false);
  for (int v : fixed) heldMeshPoints[v] = true;
  std::vector<bool> heldFreePoints = heldMeshPoints;
  // The rest shape over the free points, and the forces with its pull.
  MatrixX3 restPoints = initial.points();
  RestShapeForce rest;
  std::vector<ForceModel*> allForces = forces;
  if (options.restShape) allForces.push_back(&rest);
  ControlMesh mesh = initial;
  SparseMatrix freeBasis;                           // LevelModel::freeBasis of the next level
  MatrixX3 freePoints = mesh.points();              // and its free points
  int initialIsolation = options.origin.isolation;  // -1 until the first level's surface sets it
  double timeStep = options.integrator.timeStep;
  // Levels are held through pointers and built in place: Eigen 3.4's
  // sparse matrices have no move, so moving a level would copy its tables.
  std::future<std::unique_ptr<LevelModel>> prepared;  // the next level's, when built ahead
  for (int level = options.origin.level;; ++level) {
    auto started = std::chrono::steady_clock::now();
    const bool wasPrepared = prepared.valid();
    // Only the level a refit starts at has been relaxed before; a prepared
    // level is never that one.
    const int relaxedBefore = level == options.origin.level ? options.origin.relaxed : 0;
    const std::unique_ptr<LevelModel> built =
        wasPrepared ? prepared.get()
                    : std::unique_ptr<LevelModel>(new LevelModel(
                          buildLevel(mesh, level, relaxedBefore, initialIsolation, options, freeBasis, freePoints)));
    if (wasPrepared) setStart(*built, freePoints);
    // A global refinement's topology does not depend on where this level
    // ends; a local one's free points do.
    if (options.prepareNextLevel && !local && level < options.maxLevel) {
      prepared = std::async(std::launch::async, [next = subdivide(mesh).mesh, level, initialIsolation, &options] {
        int isolation = initialIsolation;
        return std::unique_ptr<LevelModel>(
            new LevelModel(buildLevel(next, level + 1, 0, isolation, options, SparseMatrix(), next.points())));
      });
    }
    // A level refused as close is first run on with weaker elasticity
    // (relaxations), then refined.
    LevelModel& model = *built;
    const std::vector<int> fixedPoints = indicesOf(heldFreePoints);  // as the solvers take them
    const bool lastLevel = level >= options.maxLevel;
    FitVerdict verdict = FitVerdict::Settle;  // the last one asked of this level
    const AcceptFit asked =
        !accept ? AcceptFit() : [&](const LimitSurface& surface, const MatrixX3& controlPoints, FitAsk when) {
          if (lastLevel && when == FitAsk::LooseRule) {
            verdict = accept(surface, controlPoints, FitAsk::LastLevelLooseRule);
            if (verdict == FitVerdict::Refine) verdict = FitVerdict::Settle;
          } else {
            verdict = accept(surface, controlPoints, when);
          }
          return verdict;
        };
    int relaxed = relaxedBefore;
    for (;; ++relaxed) {
      if (relaxed > relaxedBefore) {
        started = std::chrono::steady_clock::now();
        assembleMatrices(model, model.elasticity * options.elasticityPerLevel, options);
        setStart(model, freePoints);
      }
      LevelSummary summary;
      summary.level = level;
      summary.controlVertices = mesh.vertexCount();
      summary.freeControlPoints = static_cast<int>(freePoints.rows() - fixedPoints.size());
      summary.localRefinement = freeBasis.size() != 0;
      summary.elasticity = model.elasticity;
      // A level that will be refined or relaxed may end at a looser rule.
      const bool coarse =
          accept && (!lastLevel || relaxed < options.relaxations) && options.equilibrium.coarseLevelFactor > 1.0;
      LevelEnd end = LevelEnd::Equilibrium;
      if (options.restShape) {
        rest.set(model.matrices.stiffness, restPoints);
        model.restEnergy = rest.restEnergy();
        model.energyFloor = 1e-9 * model.restEnergy;
      }
      const MatrixX3 points =
          runLevel(model, allForces, fixedPoints, options, asked, coarse, timeStep, progress, summary, end);
      summary.residual = equilibriumResidual(model, allForces, points, fixedPoints);
      mesh.setPoints(meshPoints(freeBasis, points));
      freePoints = points;
      result.steps += summary.steps;
      summary.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
      result.levels.push_back(summary);

      // An end before the full rule was asked already: refused (Coarse), or
      // accepted for good.
      if (accept && end != LevelEnd::Coarse && end != LevelEnd::Accepted && end != LevelEnd::Met) {
        asked(*model.surface, points, FitAsk::LevelEnd);
      }
      if (verdict != FitVerdict::Relax || relaxed >= options.relaxations) break;
    }
    const bool good = verdict != FitVerdict::Refine && verdict != FitVerdict::Relax;
    if (good || lastLevel) {
      result.origin = {level, initialIsolation, relaxed};
      // The result's surface is over the mesh's own points.
      result.surface = freeBasis.size() == 0 ? model.surface : std::make_shared<const LimitSurface>(mesh);
      break;
    }
    SubdividedMesh refined = subdivide(mesh);
    heldMeshPoints = heldRefinedRows(refined.subdivisionMatrix, heldMeshPoints);
    const MatrixX3 restMesh =
        options.restShape ? MatrixX3(refined.subdivisionMatrix * meshPoints(freeBasis, restPoints)) : MatrixX3();
    if (local) {
      freeBasis = refinedBasis(mesh.topology(), refined.subdivisionMatrix, freeBasis, region(mesh.topology()),
                               heldFreePoints, heldMeshPoints);
    }
    if (freeBasis.size() == 0) {
      freePoints = refined.mesh.points();
      if (options.restShape) restPoints = restMesh;
      heldFreePoints = heldMeshPoints;
    } else {
      // The free points carried keep their values; the new ones are the new
      // edge and face points' offsets from where subdivision puts them: zero
      // at the start, and in the rest shape.
      freePoints = withNewOffsets(freePoints, freeBasis.cols());
      if (options.restShape) restPoints = withNewOffsets(restPoints, freeBasis.cols());
      heldFreePoints.resize(freeBasis.cols(), false);  // the new points move
    }
    mesh = std::move(refined.mesh);
  }
  result.mesh = std::move(mesh);
  return result;
}

}  // namespace dynsub
