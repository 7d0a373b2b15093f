#pragma once
// Multilevel dynamics (TVCG 1998 §2.5.1, §3.3-3.4; ICCV 1998 §3): the control
// points evolve under M p'' + D p' + K p = f_p, integrated implicitly
// (Integrator.h), until equilibrium, or, with IntegrationScheme::Static, go
// to the equilibrium K p = f_p by Newton steps (StaticSolver.h: the same
// equilibria in tens of solves, for forces with a potential the energy
// falls at every step); then, unless the caller accepts the fit,
// the control mesh is replaced by its global Catmull-Clark refinement
// (p' = A p: the limit surface is unchanged), the matrices are rebuilt and the
// evolution goes on, up to `maxLevel` refinements.
//
// Equilibrium: a step is still when it changes the total energy (kinetic +
// elastic + force potentials) by at most `energyTolerance` of its magnitude
// and moves the limit surface *across itself* (along its normals, at the
// quadrature points) by at most `motionTolerance` of the model's size
// (bounding-box diagonal of the control points at the level start). Time
// stepping is at equilibrium after `window` still steps in a row, the static
// scheme after two. A level that reaches `maxSteps` first ends unconverged
// (and is reported so).
//
// The motion along the surface is left out: steps also slide the
// parametrization along the surface, a creep that changes neither the shape
// nor the fit. The static scheme leaves that slide to the surface's weak
// elasticity (StaticSolver.h), so waiting for it to stop would take most of
// a level's steps; time steps creep the same way. What it leaves is
// reported: LevelSummary::residual includes the tangential imbalance.
//
// Stabilizer updates (time stepping): the forces' stiffness that stabilizes the integration
// (Integrator.h) is frozen when a level starts; when the energy rises by more
// than energyTolerance for 3 steps in a row (springs re-attached elsewhere
// have made it stale) it is frozen anew at the current state and the
// left-hand matrix refactored.
//
// Divergence: a non-finite state, an energy above 1e3 times the largest seen
// in the level's first step, or a step moving a point by more than the model's
// size restarts the level from its initial state with half the time step (and
// a fresh stabilizing stiffness); after `maxTimeStepHalvings` the simulation
// stops with a dynsub::Error. Divergences come in a level's first steps, when
// the forces are strongest: once the energy has fallen for
// `timeStepRegrowth` steps running, a halved step is doubled again (the
// left-hand matrix refactored), up to the step asked for. A level that then
// diverges at a regrown step restarts at the step it started with, and grows
// no more to half of the step that diverged, or beyond.
// A step left halved for the rest of the simulation can make a level too
// slow to settle within maxSteps (Documentation/Segmentation.md, "The time
// step after a divergence").
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "dynsub/ControlMesh.h"
#include "dynsub/ForceModel.h"
#include "dynsub/Integrator.h"
#include "dynsub/PhysicalMatrices.h"

namespace dynsub {

struct EquilibriumOptions {
  double energyTolerance = 1e-4;  // relative change per step
  double motionTolerance = 1e-4;  // per step, fraction of the model size
  int window = 5;                 // steps
  int maxSteps = 1000;            // per level
  // With a fit to accept (simulate's `accept`), in either scheme: a level
  // below the maximum is asked whether its fit is accepted at its first state
  // within tolerances this many times looser. If not, it ends there and is
  // refined (its equilibrium was only where the next level starts); if so, it
  // goes on unchanged to the full rule. 1: every level settles to the full rule.
  double coarseLevelFactor = 1.0;
};

// A control mesh's place in a multilevel fit: `level` global refinements of
// the initial model, whose patches needed `isolation` levels to isolate its
// extraordinary vertices (LimitSurface::isolationLevels; -1: the mesh is the
// initial model itself), and the relaxations its level had run
// (SimulationOptions::relaxations): a refit continues at their weaker
// elasticity, with only the relaxations left.
struct LevelOrigin {
  int level = 0;
  int isolation = -1;
  int relaxed = 0;
};

struct SimulationOptions {
  Material material;
  AssemblyOptions assembly;  // elementSize is set per level by the simulation
  IntegratorOptions integrator;
  EquilibriumOptions equilibrium;
  int maxLevel = 0;  // global refinements allowed (counted from the initial model)
  // Where the initial mesh stands: a refit that starts from an earlier
  // result's mesh continues that result's levels (SimulationResult::origin),
  // so its elasticity, element sizes and refinement budget are the ones the
  // earlier fit had reached; every point of its mesh is free (a local
  // refinement's free basis is not carried). The default is a fresh start.
  LevelOrigin origin;
  // The shape the surface's elasticity holds: false, none (the papers'
  // model: tension and rigidity resist any stretch and bend, so a closed
  // surface that forces pull in one place shrinks everywhere else); true, the
  // initial mesh's (its energy is that of the departure p - p0, p0 the
  // initial control points, carried through refinement as the points are).
  bool restShape = false;
  // Tension and rigidity at level g are multiplied by elasticityPerLevel^g.
  // 1 keeps the physics of the initial model (the energy of a surface does not
  // depend on the level); < 1 lets each refinement trade smoothing for detail.
  double elasticityPerLevel = 1.0;
  // A level whose fit is refused as close (FitVerdict::Relax) is run on from
  // where it ended with its elasticity weakened by elasticityPerLevel again,
  // up to this many times, before it is refined. A coarse surface's tension
  // and plate hold it off data it could reach (the faces of a cube bow in),
  // and refining costs four times the control vertices.
  int relaxations = 0;
  // 12 takes segment's 4 s step to 1 ms: a start a few mm across pulled by
  // landmarks 20 mm away (a small --init mesh in a caudate's clicks) moves
  // by more than its size in a step until about 4 ms. A divergence shows in
  // a level's first steps, so each restart costs a few steps.
  int maxTimeStepHalvings = 12;
  // Steps of falling energy after which a halved time step is doubled again
  // (see above; 0: a halved step stays halved). Chosen on the evaluation's
  // tuning split; only simulations in which a level diverged are affected
  // (a later level starts at the step the last one ended with).
  int timeStepRegrowth = 30;
  int quadraturePoints = 3;  // per direction per element, for distributed forces
  // Build the next level's tables (its limit surface, matrices and
  // quadrature: they depend on the refined mesh's topology alone) on a second
  // thread while this level runs, up to maxLevel. For small models whose levels
  // run on one core (segmentation); the results are the same either way. A
  // level that ends the simulation waits for the build it no longer needs.
  bool prepareNextLevel = false;
};

struct LevelSummary {
  int level = 0;  // global refinements of the initial control mesh
  int controlVertices = 0;
  // The control points that move: controlVertices less the fixed ones, or
  // fewer where the refinement was local (RefineRegion).
  int freeControlPoints = 0;
  // The level moved over a free basis (local refinement). False where it was
  // not asked for, and where simulate refined globally instead (see
  // RefineRegion and simulate).
  bool localRefinement = false;
  // The factor on tension and rigidity: elasticityPerLevel^(level + relaxations run).
  double elasticity = 1.0;
  int steps = 0;
  bool converged = false;  // ended by a rule below (equilibrium, or met), not by maxSteps
  // The level ended at the looser rule of EquilibriumOptions::coarseLevelFactor:
  // its fit was not accepted there, and it was refined or relaxed, or it
  // was accepted for good (FitVerdict::Stop).
  bool coarse = false;
  // The level ended after a step where the fit was met (FitAsk::Step),
  // before either equilibrium rule.
  bool met = false;
  double timeStep = 0;  // the step the level ended with
  // Times the level diverged and started again (with half the step, or at its
  // starting step after a regrown one diverged); `steps` counts the last start.
  int divergences = 0;
  double energy = 0;    // N mm, at the end of the level
  double seconds = 0;   // wall time of the level, assembly included
  int solverIterations = 0;
  // Time stepping: times the forces' stiffness was re-frozen (see above);
  // static: diagonal shifts needed to factor the Newton system.
  int stabilizerUpdates = 0;
  // |f_p - K p| / max(|f_p|, |K p|) at the end of the level (Frobenius
  // norms over the free control vertices): how far the papers' equilibrium
  // equation K p = f_p is from holding; 0 exactly at equilibrium.
  double residual = 0;
};

struct SimulationResult {
  ControlMesh mesh;  // the final control mesh (points at the final state)
  std::vector<LevelSummary> levels;
  int steps = 0;  // over all levels
  LevelOrigin origin;  // of `mesh`: what a refit from it passes as SimulationOptions::origin
  // The last level's limit surface (of `mesh`'s topology), for the outputs,
  // so that they need not build it again.
  std::shared_ptr<const LimitSurface> surface;
};

struct Progress {
  int level = 0;
  int step = 0;
  double energy = 0;
  // Largest move of a free point in the step, mm: a control point's, or
  // with local refinement a free point's or offset's (RefineRegion).
  double motion = 0;
  // The state after the step, for observers that measure a fit or draw the
  // surface. Valid only during the callback; the callback may throw to stop
  // the simulation (the exception propagates out of simulate).
  const LimitSurface* surface = nullptr;
  const MatrixX3* controlPoints = nullptr;
  // Shape recovery in the static scheme (fitPointCloud): each data point's
  // distance (mm) to the surface at this state, which the data springs
  // measured for the step's last force evaluation. Null otherwise (the time
  // steps evaluate forces before they move).
  const Eigen::VectorXd* dataDistances = nullptr;
};

// Whether the fit is good enough, and when it is asked:
//  - Step: after every step, at the state the forces were last evaluated at
//    (`controlPoints`). It is asked often, so the answer should come from
//    what the forces measured there, with a new measurement only where that
//    says the fit may be met. Stop ends the simulation at this state; the
//    other verdicts go on.
//  - LooseRule: a level below the maximum first meets the looser rule of
//    EquilibriumOptions::coarseLevelFactor (the forces were last evaluated
//    at `controlPoints`).
//  - LastLevelLooseRule: the same, on the last level while it has a
//    relaxation left. Relax ends it there to be relaxed; Refine, with
//    nothing to refine into, is taken as Settle.
//  - LevelEnd: the level ended, the last one included.
// The verdicts:
//  - Refine: not yet; the level ends (there, if asked at the looser rule)
//    and is refined.
//  - Relax: not yet, but close; the level ends as for Refine and is run on
//    with weaker elasticity (SimulationOptions::relaxations) before it is
//    refined. Refine when no relaxation is left.
//  - Settle: good so far; a level asked before its end goes on to the full
//    rule and is asked again there. At a level's end, the same as Stop.
//  - Stop: good; the simulation ends at this state.
enum class FitAsk { Step, LooseRule, LastLevelLooseRule, LevelEnd };
enum class FitVerdict { Refine, Relax, Settle, Stop };
using AcceptFit = std::function<FitVerdict(const LimitSurface& surface, const MatrixX3& controlPoints, FitAsk when)>;
using ProgressCallback = std::function<void(const Progress&)>;

// Local refinement (hierarchical, as hierarchical B-splines refine): asked
// when a level is refined, with that level's control mesh, the faces whose refinement
// the fit needs. The mesh is still subdivided everywhere, so the surface and
// its elements are global refinement's, exactly; but only the edge and face
// points of the faces named become new free control points. Every other
// point of the refined mesh stays where subdivision puts it from the free
// points before, so away from those faces the surface keeps the coarser
// level's shape and freedom (the level is solved for the free points alone,
// over LimitSurface.h's free basis). Used by the static scheme only
// (takesRefineRegion); without
// it, when every face is named on a mesh whose points are all free, or where
// the free points would not stay independent, every point of the refined
// mesh is free.
using RefineRegion = std::function<std::vector<int>(const Topology& mesh)>;

// `faces` and every face within `rings` rings of them (sharing a vertex);
// every face of the mesh when `faces` is empty: a RefineRegion's answer
// from the faces where a fit is refused.
std::vector<int> grownFaces(const Topology& mesh, const std::vector<int>& faces, int rings);

// forces are not owned. fixed: control vertices of the initial mesh that do not
// move within a level. They keep their numbers through refinement, which
// puts each where the subdivision rules do (an interior one's vertex point
// blends its neighbours, so it moves with them; a boundary one's blends boundary
// points alone, so it stays where those are held too), and each refinement holds as well every
// new point that the held points alone determine: an open mesh's held
// boundary stays where it is, its new vertex and edge points included.
// With `region`, a held point that a free point would move (an interior vertex
// held alone: its vertex point blends its neighbours) makes that refinement
// global.
// Throws dynsub::Error on bad options or unrecoverable divergence.
SimulationResult simulate(const ControlMesh& initial, const std::vector<ForceModel*>& forces,
                          const std::vector<int>& fixed, const SimulationOptions& options,
                          const AcceptFit& accept = nullptr, const ProgressCallback& progress = nullptr,
                          const RefineRegion& region = nullptr);

// The control vertices that simulate holds after a refinement (subdivision:
// the refined mesh's points from the coarse ones), `fixed` holding the coarse
// mesh's: the fixed ones, which keep their numbers, and every refined point
// that they alone determine. Sorted.
std::vector<int> refinedFixedVertices(const SparseMatrix& subdivision, const std::vector<int>& fixed);

// Whether simulate refines locally when given a RefineRegion: under the static
// scheme only (see above).
bool takesRefineRegion(const SimulationOptions& options);

void checkSimulationOptions(const SimulationOptions& options);

}  // namespace dynsub
