#include "dynsub/Deformation.h"

#include <cmath>

#include "dynsub/ClosestPoint.h"
#include "dynsub/EnclosingSphere.h"
#include "dynsub/Error.h"
#include "dynsub/ForceModel.h"
#include "dynsub/LimitSurface.h"
#include "dynsub/ShapeRecovery.h"

namespace dynsub {

SimulationOptions DeformationOptions::defaultSimulation() {
  SimulationOptions o;
  // Springs held at their attachments are linear: the static scheme's first
  // Newton step is the level's exact equilibrium (Data/Deform/torus_pull:
  // residual 4e-15 after 3 steps, where first-order time steps stop at 1e-2
  // after 262).
  o.integrator.scheme = IntegrationScheme::Static;
  o.maxLevel = 0;
  // Modeling changes a shape where it is pulled: without a rest shape the
  // tension would shrink the rest of a closed model (the torus pull flattens
  // its tube to a tenth of its height; Dynamics.md).
  o.restShape = true;
  return o;
}

bool DeformationOptions::refinesLocally() const { return localRefinement && takesRefineRegion(simulation); }

DeformationResult deformSurface(const ControlMesh& initial, const MatrixX3& targets, const Eigen::VectorXd& stiffness,
                                const std::vector<int>& fixed, const DeformationOptions& options,
                                const ProgressCallback& progress) {
  if (targets.rows() == 0) throw Error("a deformation needs at least one spring");
  if (!(options.tolerancePercent > 0) || !std::isfinite(options.tolerancePercent))
    throw Error("the deformation's tolerance must be a finite number > 0 (percent of the model's diameter)");
  DeformationResult result;
  MatrixX3 extent(initial.vertexCount() + targets.rows(), 3);
  extent << initial.points(), targets;
  result.diameter = 2.0 * smallestEnclosingSphere(extent).radius;
  if (!(result.diameter > 0)) throw Error("the control mesh and the springs' targets are all one point");
  result.localRefinement = options.refinesLocally();

  SpringForceModel springs(targets, stiffness, SpringForceModel::Attach::NearestAtLevelStart);
  // The faces, of the level last measured, that hold a target's nearest
  // surface point farther than the tolerance.
  std::vector<int> facesToRefine;
  // Each level runs to its equilibrium (one or two Newton steps: the springs
  // are linear within a level), and is refined if a target is still too far.
  // A refinement that brings the farthest target less than
  // kLeastRefinementGain closer ends the refinement (see the header). Every
  // level's distance is recorded once, where the level ends: refused at the
  // looser rule, or at its end, which the last level always reaches (its
  // looser rule is never refused), so the last one recorded is the final
  // surface's.
  const AcceptFit accept = [&](const LimitSurface& surface, const MatrixX3& points, FitAsk when) {
    if (when == FitAsk::Step) return FitVerdict::Settle;
    std::vector<ClosestPoint> nearest;
    const double distance = measureFitError(surface, points, targets, result.diameter, nullptr, &nearest).maxPercent;
    if (result.localRefinement)
      facesToRefine = facesFartherThan(surface, nearest, result.diameter, options.tolerancePercent);
    const bool gained = result.levelDistancesPercent.empty() ||
                        distance < (1.0 - kLeastRefinementGain) * result.levelDistancesPercent.back();
    const bool refine = distance > options.tolerancePercent && gained && when != FitAsk::LastLevelLooseRule;
    if (refine || when == FitAsk::LevelEnd) result.levelDistancesPercent.push_back(distance);
    return refine ? FitVerdict::Refine : FitVerdict::Settle;
  };
  RefineRegion region;
  if (result.localRefinement) {
    region = [&](const Topology& mesh) { return grownFaces(mesh, facesToRefine, kRefineRings); };
  }
  SimulationResult simulation = simulate(initial, {&springs}, fixed, options.simulation, accept, progress, region);
  result.mesh = std::move(simulation.mesh);
  result.surface = std::move(simulation.surface);
  result.levels = std::move(simulation.levels);
  result.steps = simulation.steps;
  if (result.levelDistancesPercent.size() != result.levels.size())
    throw Error("internal: a deformation's level ended without its distance measured");
  result.maxDistancePercent = result.levelDistancesPercent.back();
  result.toleranceMet = result.maxDistancePercent <= options.tolerancePercent;
  result.springLengths = springs.lengths();
  return result;
}

}  // namespace dynsub
