#include "dynsub/Simulation.h"

#include <chrono>
#include <cmath>
#include <deque>
#include <string>

#include "dynsub/CatmullClark.h"
#include "dynsub/Error.h"
#include "dynsub/LimitSurface.h"

namespace dynsub {

namespace {

double modelSize(const Matrix3X& points) {
  return (points.colwise().maxCoeff() - points.colwise().minCoeff()).norm();
}

// sum over x, y, z of a^T A a.
double quadraticForm(const SymmetricMatrix& a, const Matrix3X& x) { return (x.array() * (a * x).array()).sum(); }

struct LevelState {
  ControlMesh mesh;
  int level = 0;
  double elementSize = 1.0;
};

}  // namespace

void checkSimulationOptions(const SimulationOptions& o) {
  checkMaterial(o.material);
  const EquilibriumOptions& e = o.equilibrium;
  if (!(e.energyTolerance > 0.0) || !(e.motionTolerance > 0.0) || e.window < 1 || e.maxSteps < 1) {
    throw Error("equilibrium tolerances must be > 0, the window and the step limit >= 1");
  }
  if (o.maxLevel < 0 || o.maxLevel > 6) throw Error("the maximum level must be in 0..6, got " + std::to_string(o.maxLevel));
  if (o.maxTimeStepHalvings < 0) throw Error("time-step halvings must be >= 0");
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

SimulationResult simulate(const ControlMesh& initial, const std::vector<ForceModel*>& forces,
                          const std::vector<int>& fixed, const SimulationOptions& options, const AcceptFit& accept,
                          const ProgressCallback& progress) {
  checkSimulationOptions(options);
  for (int v : fixed) {
    if (v < 0 || v >= initial.vertexCount()) {
      throw Error("fixed control vertex " + std::to_string(v) + " does not exist (the mesh has " +
                  std::to_string(initial.vertexCount()) + ")");
    }
  }
  SimulationResult result;
  LevelState state{initial, 0, 1.0};
  // Element sides are measured in elements of the initial model: a base mesh
  // that is `b` global refinements past the initial one has side 2^-b.
  int initialIsolation = 0;  // set from the first level's surface
  double timeStep = options.integrator.timeStep;

  for (;;) {
    const auto started = std::chrono::steady_clock::now();
    const LimitSurface surface(state.mesh);
    if (state.level == 0) initialIsolation = surface.isolationLevels();
    state.elementSize = std::ldexp(1.0, initialIsolation - (state.level + surface.isolationLevels()));
    AssemblyOptions assembly = options.assembly;
    assembly.elementSize = state.elementSize;
    Material material = options.material;
    const double elasticity = std::pow(options.elasticityPerLevel, state.level);
    for (double* m : {&material.tensionU, &material.tensionV, &material.rigidityUU, &material.rigidityUV,
                      &material.rigidityVV}) {
      *m *= elasticity;
    }
    const PhysicalMatrices matrices = assemblePhysicalMatrices(surface, material, assembly);
    const SurfaceQuadrature quadrature =
        makeSurfaceQuadrature(surface, options.quadraturePoints, state.elementSize);
    const Matrix3X start = state.mesh.points();
    const double size = modelSize(start);
    if (!(size > 0.0)) throw Error("the control mesh has no extent");

    LevelSummary summary;
    summary.level = state.level;
    summary.controlVertices = state.mesh.vertexCount();
    Matrix3X current;
    for (int halvings = 0;; ++halvings) {
      if (halvings > options.maxTimeStepHalvings) {
        throw Error("the simulation diverged at level " + std::to_string(state.level) + " even with time step " +
                    std::to_string(timeStep * 2.0) + " s (try a smaller --time-step or softer forces)");
      }
      for (ForceModel* f : forces) f->beginLevel(surface, quadrature, start);
      IntegratorOptions integratorOptions = options.integrator;
      integratorOptions.timeStep = timeStep;
      // The stabilizing stiffness of the forces at `points` (Integrator.h).
      auto makeIntegrator = [&](const Matrix3X& points) {
        SymmetricMatrix stabilizing(points.rows(), points.rows());
        for (ForceModel* f : forces) {
          const SparseMatrix s = f->stabilizingStiffness(points);
          if (s.size() > 0) stabilizing += SymmetricMatrix(s);
        }
        return Integrator(matrices, stabilizing, fixed, integratorOptions);
      };
      Integrator integrator = makeIntegrator(start);

      Matrix3X previous = start;
      current = start;
      std::deque<std::pair<double, double>> recent;  // (relative energy change, relative motion)
      double lastEnergy = std::numeric_limits<double>::quiet_NaN();
      double firstEnergy = 0.0;
      int rises = 0;
      bool diverged = false;
      summary.steps = 0;
      summary.converged = false;
      summary.solverIterations = 0;
      summary.stabilizerUpdates = 0;
      for (int step = 1; step <= options.equilibrium.maxSteps; ++step) {
        // Forces and the energy of the current state.
        double potential = 0.0;
        Matrix3X force = Matrix3X::Zero(current.rows(), 3);
        for (ForceModel* f : forces) force += f->generalizedForce(current, potential);
        const Matrix3X velocity = (current - previous) / timeStep;
        const double energy = 0.5 * quadraticForm(matrices.mass, velocity) +
                              0.5 * quadraticForm(matrices.stiffness, current) + potential;
        if (step == 1) firstEnergy = std::abs(energy);
        if (!std::isfinite(energy) || std::abs(energy) > 1e3 * std::max(firstEnergy, 1e-300)) {
          diverged = true;
          break;
        }
        if (step > 1) {
          const double change =
              std::abs(energy - lastEnergy) / std::max({std::abs(energy), std::abs(lastEnergy), 1e-300});
          recent.emplace_back(change, (current - previous).rowwise().norm().maxCoeff() / size);
          if (static_cast<int>(recent.size()) > options.equilibrium.window) recent.pop_front();
          // The motion is dissipative and re-attaching springs only lowers
          // their energy, so an energy that keeps rising means the forces'
          // stiffness has drifted from the one the integrator was built with.
          // Changes within the equilibrium tolerance are not rises: near an
          // equilibrium they are noise (and forces without a potential, like
          // image forces, make the counted energy wander by that much).
          rises = change > options.equilibrium.energyTolerance && energy > lastEnergy ? rises + 1 : 0;
          if (rises >= 3) {
            integrator = makeIntegrator(current);
            ++summary.stabilizerUpdates;
            rises = 0;
            recent.clear();
          }
        }
        lastEnergy = energy;
        summary.energy = energy;
        if (static_cast<int>(recent.size()) == options.equilibrium.window) {
          bool still = true;
          for (const auto& [change, move] : recent) {
            still = still && change <= options.equilibrium.energyTolerance && move <= options.equilibrium.motionTolerance;
          }
          if (still) {
            summary.converged = true;
            break;
          }
        }

        Matrix3X next = integrator.step(previous, current, force);
        summary.solverIterations += integrator.lastIterations();
        const double motion = (next - current).rowwise().norm().maxCoeff();
        if (!next.allFinite() || motion > size) {
          diverged = true;
          break;
        }
        previous = std::move(current);
        current = std::move(next);
        summary.steps = step;
        if (progress) progress(Progress{state.level, step, energy, motion, &surface, &current});
      }
      if (!diverged) break;
      timeStep *= 0.5;
    }
    summary.timeStep = timeStep;
    state.mesh.setPoints(current);
    result.steps += summary.steps;
    summary.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
    result.levels.push_back(summary);

    const bool good = accept ? accept(surface, current) : true;
    if (good || state.level >= options.maxLevel) break;
    state.mesh = subdivide(state.mesh).mesh;
    ++state.level;
  }
  result.mesh = std::move(state.mesh);
  return result;
}

}  // namespace dynsub
