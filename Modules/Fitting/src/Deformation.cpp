#include "dynsub/Deformation.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "dynsub/CatmullClark.h"
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

namespace {
// Samples of the turned-over measure over the whole surface, at any level:
// its share is resolved to about 1/4096 of the area (0.025 %), well below the
// kRestartTurnedOverPercent that starts a level again.
constexpr int kTurnedOverSamples = 4096;
}  // namespace

double turnedOverAreaPercent(const LimitSurface& before, const MatrixX3& beforePoints, const LimitSurface& after,
                             const MatrixX3& afterPoints) {
  if (before.elementCount() != after.elementCount())
    throw Error("internal: surfaces of different meshes compared for turned-over area");
  SurfaceState initialState(before), finalState(after);
  initialState.reset(beforePoints);
  finalState.reset(afterPoints);
  // An n x n midpoint grid on each element, n such that the surface has about
  // kTurnedOverSamples points or more at any level, each weighted by the
  // input's area element.
  const int elements = before.elementCount();
  const int n = std::clamp(static_cast<int>(std::ceil(std::sqrt(double(kTurnedOverSamples) / elements))), 1, 16);
  double area = 0.0, turned = 0.0;
  for (int element = 0; element < elements; ++element) {
    for (int i = 0; i < n; ++i) {
      for (int j = 0; j < n; ++j) {
        const ElementPoint point{element, (i + 0.5) / n, (j + 0.5) / n};
        const LimitSample initial = initialState.evaluate(point);
        const double weight = initial.du.cross(initial.dv).norm();
        area += weight;
        if (initial.normal.dot(finalState.evaluate(point).normal) < 0.0) turned += weight;
      }
    }
  }
  return area > 0.0 ? 100.0 * turned / area : 0.0;
}

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
  // The level the next verdict is asked of, and the farthest target's
  // distance at the level before it (none before a run's first level).
  int level = options.simulation.origin.level;
  double previousDistance = std::numeric_limits<double>::infinity();
  // The input refined to the level last measured, its surface (when that
  // level's is over a free basis), its held vertices, and its level.
  ControlMesh inputAtLevel = initial;
  std::unique_ptr<LimitSurface> inputSurface;
  std::vector<int> heldAtLevel = fixed;
  int inputLevel = level;
  const auto refineInput = [&] {
    SubdividedMesh refined = subdivide(inputAtLevel);
    heldAtLevel = refinedFixedVertices(refined.subdivisionMatrix, heldAtLevel);
    inputAtLevel = std::move(refined.mesh);
    inputSurface.reset();
    ++inputLevel;
  };
  bool turnedOver = false;  // the run ended at a level that turned over, with a finer one allowed
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
    const bool gained = distance < (1.0 - kLeastRefinementGain) * previousDistance;
    const bool refine = distance > options.tolerancePercent && gained && when != FitAsk::LastLevelLooseRule;
    if (!refine && when != FitAsk::LevelEnd) return FitVerdict::Settle;
    result.levelDistancesPercent.push_back(distance);
    previousDistance = distance;
    // Every refinement, local ones too, subdivides the whole mesh.
    while (inputLevel < level) refineInput();
    if (LimitSurface::elementCountOf(inputAtLevel) != surface.elementCount())
      throw Error("internal: a deformation's level is not its input refined as often");
    // A level without a free basis is a surface of the input's mesh itself.
    const bool sameMesh = surface.controlVertexCount() == inputAtLevel.vertexCount();
    if (!sameMesh && !inputSurface) inputSurface = std::make_unique<LimitSurface>(inputAtLevel);
    const double turned =
        turnedOverAreaPercent(sameMesh ? surface : *inputSurface, inputAtLevel.points(), surface, points);
    result.levelTurnedOverPercent.push_back(turned);
    // A fold is no shape to refine (the next level's springs would attach
    // to it): the run ends here and starts again below.
    turnedOver = turned >= kRestartTurnedOverPercent && level < options.simulation.maxLevel;
    if (turnedOver) return FitVerdict::Stop;
    if (refine) ++level;
    return refine ? FitVerdict::Refine : FitVerdict::Settle;
  };
  RefineRegion region;
  if (result.localRefinement) {
    region = [&](const Topology& mesh) { return grownFaces(mesh, facesToRefine, kRefineRings); };
  }
  ControlMesh start = initial;
  std::vector<int> held = fixed;
  SimulationOptions simulationOptions = options.simulation;
  for (;;) {
    SimulationResult simulation = simulate(start, {&springs}, held, simulationOptions, accept, progress, region);
    result.mesh = std::move(simulation.mesh);
    result.surface = std::move(simulation.surface);
    result.levels.insert(result.levels.end(), simulation.levels.begin(), simulation.levels.end());
    result.steps += simulation.steps;
    if (!turnedOver) break;
    // Start again from the input refined past the level that turned over,
    // where the springs attach to the input's surface, as at level 0.
    refineInput();
    result.restarts.push_back(static_cast<int>(result.levels.size()));
    level = inputLevel;
    previousDistance = std::numeric_limits<double>::infinity();
    start = inputAtLevel;
    held = heldAtLevel;
    simulationOptions.origin = {level, simulation.origin.isolation, 0};
  }
  if (result.levelDistancesPercent.size() != result.levels.size() ||
      result.levelTurnedOverPercent.size() != result.levels.size())
    throw Error("internal: a deformation's level ended without its distance measured");
  result.maxDistancePercent = result.levelDistancesPercent.back();
  result.toleranceMet = result.maxDistancePercent <= options.tolerancePercent;
  result.springLengths = springs.lengths();
  result.turnedOverPercent = result.levelTurnedOverPercent.back();
  if (result.mesh.vertexCount() == inputAtLevel.vertexCount()) {
    const MatrixX3 moved = result.mesh.points() - inputAtLevel.points();
    const Eigen::RowVector3d shift = moved.colwise().mean();
    result.commonShiftMm = shift.norm();
    result.largestDepartureMm = (moved.rowwise() - shift).rowwise().norm().maxCoeff();
  }
  return result;
}

}  // namespace dynsub
