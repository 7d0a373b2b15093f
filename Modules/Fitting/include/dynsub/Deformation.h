#pragma once
// Modeling by forces (TVCG §4.1, Fig. 6): springs from points in space to
// the nearest points of the limit surface pull it to a new equilibrium.
//
// The surface is refined while a target is farther from it than the
// tolerance, up to the simulation's maxLevel, and only where: the faces that
// hold such a target's nearest surface point, and kRefineRings rings around
// them, get new free control points (RefineRegion, Simulation.h); elsewhere
// the refined mesh follows the coarser level. A pull on a few points then
// adds detail where they pull, not over the whole surface, as global
// refinement (`localRefinement` false, as the papers do) would. The distance
// is measured, as the fit's error is, to the nearest point of the exact
// limit surface, in percent of the diameter of the smallest sphere enclosing
// the initial control points and the targets: a unit-free tolerance, and a
// single target still has a model to measure against.
#include <memory>
#include <vector>

#include "dynsub/ControlMesh.h"
#include "dynsub/Simulation.h"

namespace dynsub {

// A refinement must bring the farthest target at least this share closer,
// or refinement ends there with the tolerance unmet: the springs' pull is
// then balanced by the surface's elasticity, which a finer mesh does not
// weaken (its energy does not depend on the level; elasticityPerLevel 1),
// and a finer level would cost four times the control vertices for nothing.
constexpr double kLeastRefinementGain = 0.1;

// A level whose surface turns this share of its area over (percent;
// DeformationResult::turnedOverPercent), with a finer level allowed, is not
// refined but started again finer (deformSurface). A smaller fold is kept
// and reported: a pull may bend a small region over by more than 90 degrees,
// and a restart frees every point of its level, as global refinement does.
constexpr double kRestartTurnedOverPercent = 1.0;

struct DeformationOptions {
  // The largest distance from a target to the surface that ends refinement,
  // percent of the diameter (see above).
  double tolerancePercent = 1.0;
  // Refine only near the targets still too far (the static scheme only);
  // false: every face.
  bool localRefinement = true;
  SimulationOptions simulation = defaultSimulation();

  // The static scheme, no refinement, the initial shape at rest.
  static SimulationOptions defaultSimulation();
  // Whether refinement is local.
  bool refinesLocally() const;
};

struct DeformationResult {
  ControlMesh mesh;
  std::shared_ptr<const LimitSurface> surface;  // mesh's limit surface
  std::vector<LevelSummary> levels;
  int steps = 0;
  double diameter = 0;            // mm, the tolerance's reference length
  double maxDistancePercent = 0;  // the farthest target from the final surface
  bool toleranceMet = false;
  // Whether local refinement was asked for and the scheme takes it; each
  // level's LevelSummary::localRefinement says whether it was done.
  bool localRefinement = false;
  Eigen::VectorXd springLengths;              // mm, each spring's at its last evaluation
  std::vector<double> levelDistancesPercent;  // the farthest target, at each level's end
  // The share of the input surface's area, percent, whose normal the final
  // surface turns against itself (their dot product < 0, compared at the same
  // parameters): the surface has folded through itself.
  // Springs far stiffer than the elasticity on a level too coarse to form
  // their shape do that (an unanchored bump on the cube); so does a closed
  // surface shrinking without a rest shape, and a pull that bends a region
  // over by more than 90 degrees reads here too.
  double turnedOverPercent = 0;
  std::vector<double> levelTurnedOverPercent;  // the same, at each level's end
  // The mean of the control points' displacements from the input refined to
  // the final level (mm; its length), and the farthest any point's
  // displacement lies from that mean: a surface that nothing holds away from
  // the springs moves as a whole, keeping its shape, since a translation costs
  // its elasticity nothing (with or without a rest shape).
  double commonShiftMm = 0;
  double largestDepartureMm = 0;
  // The levels (indices into `levels`) that started again from the input
  // mesh refined to them, because the level before turned over (see
  // deformSurface); every point of such a level is free.
  std::vector<int> restarts;
};

// The share (percent) of the area of surface `before` (at its control points
// beforePoints) whose normal `after` reverses, compared on an n x n midpoint
// grid of each element, n = ceil(sqrt(4096 / elements)) up to 16. The two
// surfaces are of one mesh's elements; `after` may be over a free basis
// (Simulation.h's RefineRegion).
double turnedOverAreaPercent(const LimitSurface& before, const MatrixX3& beforePoints, const LimitSurface& after,
                             const MatrixX3& afterPoints);

// A level that turns kRestartTurnedOverPercent or more over, with a finer
// level allowed, is not refined: its refinement's springs would attach to the
// fold's nearest points, some on its wrong side. The deformation starts again
// from the input mesh refined once past it, whose finer surface can form more
// of what the springs ask, with the springs attached to the input's surface as
// at level 0, and the refinement's gain measured from there on.
//
// targets: #springs x 3 (mm); stiffness: one per spring (N/mm), > 0. fixed:
// control vertices of `initial` that do not move. Throws dynsub::Error on bad
// input or unrecoverable divergence.
DeformationResult deformSurface(const ControlMesh& initial, const MatrixX3& targets, const Eigen::VectorXd& stiffness,
                                const std::vector<int>& fixed, const DeformationOptions& options,
                                const ProgressCallback& progress = nullptr);

}  // namespace dynsub
