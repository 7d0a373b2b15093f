#pragma once
// Shape recovery from range data (TVCG 1998 §4.2; ICCV 1998 §3-4): springs
// from every data point to its nearest point on the limit surface pull an
// initial model, inside the data, onto the data; at each equilibrium the fit
// error is measured and, while it is above the tolerance, the control mesh is
// refined globally (Simulation.h).
//
// When to stop: the papers measure the fit at each level's equilibrium. Here
// the fit is also asked after every step, by what the data springs measured
// there: when every spring is within the tolerance (or, on noisy data, the
// bias of their signed lengths is), one closest-point search measures the
// fit, and if it is met the fit ends at that step. The steps on to the
// equilibrium would only fit closer than was asked (FitOptions::toEquilibrium
// keeps the papers' rule).
//
// Fit error (the papers' measure): the distance from each data point to the
// exact limit surface (ClosestPoint.h), as a percentage of the diameter of the
// smallest sphere enclosing the data (EnclosingSphere.h); max_error_percent
// is the largest, rms_error_percent the root mean square.
//
// Noisy data (FitOptions::noise, from ScanNoise.h): the largest distance
// from a noisy point to the true surface is about sqrt(2 ln n) sigma for n
// points, so a max error below that is out of reach and refinement would
// chase the noise to the last level. When that reach is at least half the
// tolerance, the fit is also accepted when its bias is within the tolerance:
// the largest mean of the signed distances over a point and its
// kBiasNeighbours nearest points, where the noise averages out (to sigma / 3
// per mean) and what is left is the surface's own offset from the data. The
// noise still adds up to about sqrt(2 ln n) sigma / 3 to the largest of the n
// means, so the rule errs toward refining. Clean data keep the papers' rule
// alone.
//
// Before refining, relaxing: a level refused within kRelaxWithin times the
// tolerance (its max error, or on noisy data its bias) is run on once with
// its tension and rigidity weakened 4-fold more (SimulationOptions::
// relaxations), and refined only if still refused. Such a level is often
// held off the data by its elasticity rather than short of control
// vertices, and refining would take four times as many.
//
// Spring stiffness: every data point gets k = dataStiffness x (parametric area
// of the initial model) / #points, so the balance between data and surface
// elasticity does not depend on how densely the data were sampled.
//
// Surface springs (FitOptions::surfaceSprings, off by default): the data
// springs pull only surface that some point is nearest to, and the fit's
// error, measured from the points, sees no other; a model that has not
// followed a gap (between a limb and the body) spans it with a web that
// nothing pulls and that refining keeps (SurfaceCoverage.h). Surface springs
// join each quadrature point of the surface to its nearest data point, and
// pull such webs onto the scan. On clouds sampled from CGAL's meshes at 1 %,
// 0.1 of the data springs' stiffness left 0-0.02 % of a cow's, a femur's and
// a triceratops's surface uncovered where there were 5-13 %, and 2-15 % of a
// dino's, a man's and a diplodocus's where there were 21-28 %, in 0.8-1.5
// times the time; 0.25 did no better. They are off by default: noisy scans
// fit worse with them (the kitten with 0.3 % noise and 3 % outliers ends 1.5 %
// from its clean points instead of 0.98 %), and a scan without webs only
// pays for them (Documentation/Dynamics.md, "Surface springs").
//
// Springs per element: a level whose surface has E elements is pulled by at
// most springsPerElement x E of the data's springs, a fixed random sample
// with the data's total stiffness (SpringForceModel::setSamplePerElement):
// a dense scan's coarse levels cost what their surfaces need, not what the
// scan has. Every level is still accepted or refused, and its error
// reported, by all the points.
#include <memory>
#include <string>
#include <vector>

#include "dynsub/ControlMesh.h"
#include "dynsub/EnclosingSphere.h"
#include "dynsub/InitialModels.h"
#include "dynsub/Simulation.h"

namespace dynsub {

struct ClosestPoint;

// Neighbours a point's bias is averaged over (see above). Larger means
// average the noise out further but dilute an offset confined to a narrow
// band, like the rounding of a crease: on the synthetic tuning clouds
// (Tools/tuning_clouds.py with Tools/corrupt_cloud.py) the two spheres' crease
// was 2.4 % off with 20 and 2.1 % with 8, the smooth clouds equally close
// with both, and 4 refined the noisy sphere to 1538 control vertices for
// nothing.
constexpr int kBiasNeighbours = 8;

// On the synthetic tuning clouds at tolerances of 1, 0.5, 0.25 and 0.1 %,
// 2 left as few control vertices as 1.5 and relaxing every refused level,
// and the noisy peanut closer to its true surface than either.
constexpr double kRelaxWithin = 2.0;

// On the dense synthetic tuning clouds (30,000 points; Tools/tuning_clouds.py)
// at 1, 0.5, 0.25 and 0.1 %, 32 and 64 springs per element left the control
// vertices of every fit as with all points pulling, and 16 refined the noisy
// peanut once more at 0.25 %; 64 keeps a margin of 4 over that.
constexpr double kSpringsPerElement = 64.0;

// Local refinement (FitOptions::localRefinement): the faces refined are
// those holding a data point's nearest surface point farther than the
// tolerance, and this many rings of faces around them.
constexpr int kRefineRings = 1;

struct FitOptions {
  double tolerancePercent = 1.0;  // max_error_percent that stops refinement
  double dataStiffness = 100.0;   // N/mm per unit parametric area (see above)
  double noise = 0.0;             // mm, the data's noise sigma (see above); 0: clean data
  // The springs that pull a level, per element of its surface (see above);
  // 0: every data point at every level.
  double springsPerElement = kSpringsPerElement;
  // Run the last level on to its equilibrium, as the papers do, instead of
  // ending at the first step where the tolerance is met (see above).
  bool toEquilibrium = false;
  // Refine only where the fit is refused (RefineRegion, Simulation.h; the
  // static scheme only); false: every face, as the papers do.
  bool localRefinement = true;
  // Springs from the surface to its nearest data points (see above), their
  // stiffness per unit parametric area relative to dataStiffness; 0: none,
  // the papers' fit.
  double surfaceSprings = 0.0;
  SimulationOptions simulation = defaultSimulation();

  static SimulationOptions defaultSimulation();
  // Whether the fit refines locally: asked for, and the static scheme.
  bool refinesLocally() const;
};

struct FitError {
  double maxPercent = 0;
  double rmsPercent = 0;
  double biasPercent = 0;  // noisy data only (see above), else 0
};

struct FitResult {
  ControlMesh mesh;
  std::shared_ptr<const LimitSurface> surface;  // mesh's limit surface (SimulationResult::surface)
  Sphere enclosingSphere;
  FitError error;
  std::vector<LevelSummary> levels;
  std::vector<FitError> levelErrors;  // one per level, where it ended
  int steps = 0;
  double seconds = 0;
  // The noise's reach (see above) is at least half the tolerance, and the
  // bias rule applies.
  bool noiseLimited = false;
  bool toleranceMet = false;  // by the papers' rule, or by the bias rule where it applies
};

// sqrt(2 ln n): about how many sigmas the largest of n Gaussian distances reaches.
double noiseReach(Eigen::Index points);
// Whether noise of `noise` mm on `points` points puts tolerancePercent (of
// `diameter`) out of reach of the max error, and the bias rule applies
// (see above).
bool noiseLimits(Eigen::Index points, double noise, double diameter, double tolerancePercent);

// neighbours (optional, #data x k >= kBiasNeighbours): each point's nearest
// others, for the bias. nearest (optional): each point's nearest surface point.
FitError measureFitError(const LimitSurface& surface, const MatrixX3& controlPoints, const MatrixX3& data,
                         double diameter, const Eigen::MatrixXi* neighbours = nullptr,
                         std::vector<ClosestPoint>* nearest = nullptr);

// The control faces (with repeats) that hold a point's nearest surface point,
// of `nearest` (measureFitError's), farther than tolerancePercent of
// `diameter`: where a local refinement (RefineRegion) starts.
std::vector<int> facesFartherThan(const LimitSurface& surface, const std::vector<ClosestPoint>& nearest,
                                  double diameter, double tolerancePercent);

// `initial` must be closed. Throws dynsub::Error on bad input or divergence.
FitResult fitPointCloud(const MatrixX3& data, const ControlMesh& initial, const FitOptions& options,
                        const ProgressCallback& progress = nullptr);

}  // namespace dynsub
