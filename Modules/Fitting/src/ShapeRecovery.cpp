#include "dynsub/ShapeRecovery.h"

#include <chrono>
#include <cmath>
#include <limits>
#include <memory>
#include <string>

#include <Eigen/Eigenvalues>

#include "PointTree.h"
#include "dynsub/ClosestPoint.h"
#include "dynsub/Error.h"
#include "dynsub/Forces.h"
#include "dynsub/LimitSurface.h"
#include "dynsub/ParallelFor.h"
#include "dynsub/ScanNoise.h"
#include "dynsub/StandardMeshes.h"
#include "dynsub/Tessellation.h"

namespace dynsub {


SimulationOptions FitOptions::defaultSimulation() {
  SimulationOptions o;
  // Springs to the nearest points have a potential, so Newton steps with the
  // tangent-plane stiffness reach the equilibrium with the energy falling at
  // every step (StaticSolver.h).
  o.integrator.scheme = IntegrationScheme::Static;
  o.maxLevel = 3;
  // The data springs do not stiffen with refinement; weakening the surface's
  // elasticity 4-fold per level lets the finer levels follow the data closer.
  o.elasticityPerLevel = 0.25;
  // A level that is refined ends within 30 times looser tolerances: its
  // equilibrium is only where the next level starts. Looser saves no more
  // time, the finest level being most of a fit; a level whose fit is
  // accepted still ends by the full rule.
  o.equilibrium.coarseLevelFactor = 30.0;
  o.relaxations = 1;
  return o;
}

bool FitOptions::refinesLocally() const { return localRefinement && takesRefineRegion(simulation); }

double noiseReach(Eigen::Index points) {
  return std::sqrt(2.0 * std::log(static_cast<double>(std::max<Eigen::Index>(points, 2))));
}

bool noiseLimits(Eigen::Index points, double noise, double diameter, double tolerancePercent) {
  return points > kBiasNeighbours && 100.0 * noiseReach(points) * noise / diameter >= 0.5 * tolerancePercent;
}

namespace {

// The largest mean of the signed distances over a point and its
// kBiasNeighbours nearest (the header's bias), mm.
double largestBias(const Eigen::VectorXd& signedDistances, const Eigen::MatrixXi& neighbours) {
  double bias = 0.0;
  for (Eigen::Index i = 0; i < signedDistances.size(); ++i) {
    double sum = signedDistances(i);
    for (int j = 0; j < kBiasNeighbours; ++j) sum += signedDistances(neighbours(i, j));
    bias = std::max(bias, std::abs(sum) / static_cast<double>(kBiasNeighbours + 1));
  }
  return bias;
}

// Springs from the surface to the data: at each quadrature point of the
// surface, a spring of stiffness `stiffness` x its parametric area to the
// nearest data point, found again at every evaluation. The data springs pull
// only the surface that some point is nearest to; these pull the rest too,
// such as a web across a gap between two limbs, onto the scan.
class SurfaceSprings final : public ForceModel {
 public:
  SurfaceSprings(const MatrixX3& data, double stiffness)
      : rows_{data}, tree_(3, rows_, nanoflann::KDTreeSingleIndexAdaptorParams(16)), stiffness_(stiffness) {}

  void beginLevel(const LimitSurface&, const SurfaceQuadrature& quadrature, const MatrixX3&) override {
    quadrature_ = &quadrature;
  }

  MatrixX3 generalizedForce(const MatrixX3& controlPoints, double& potential) override {
    const MatrixX3 positions = quadrature_->J * controlPoints;
    MatrixX3 pulls(positions.rows(), 3);
    Eigen::VectorXd energies(positions.rows());
    parallelFor(positions.rows(), threadsWorth(positions.rows()), [&](Eigen::Index i) {
      unsigned nearest = 0;
      double squared = 0.0;
      const Vector3 x = positions.row(i).transpose();
      tree_.knnSearch(x.data(), 1, &nearest, &squared);
      const double k = stiffness_ * quadrature_->weights(i);
      pulls.row(i) = k * (rows_.points.row(nearest) - positions.row(i));
      energies(i) = 0.5 * k * squared;
    });
    potential += energies.sum();
    return quadrature_->J.transpose() * pulls;
  }

  // k J^T W J: the exact derivative while each spring keeps its data point.
  SparseMatrix stabilizingStiffness(const MatrixX3&) override {
    const Eigen::VectorXd k = stiffness_ * quadrature_->weights;
    return SparseMatrix(quadrature_->J.transpose() * k.asDiagonal() * quadrature_->J);
  }

  bool hasPotential() const override { return true; }

 private:
  PointRows rows_;
  PointTree tree_;
  double stiffness_;
  const SurfaceQuadrature* quadrature_ = nullptr;
};

}  // namespace

FitError measureFitError(const LimitSurface& surface, const MatrixX3& controlPoints, const MatrixX3& data,
                         double diameter, const Eigen::MatrixXi* neighbours, std::vector<ClosestPoint>* nearestOut) {
  // 8 x 8 samples per control face, as the outputs (Tessellation.h):
  // isolation's elements are a half or a quarter of a face on a side, and
  // 8 x 8 per element would make the locator's samples, and this
  // measurement, four or sixteen times as costly.
  ClosestPointLocator locator(surface, outputSegments(surface), 8);
  locator.update(controlPoints);
  std::vector<ClosestPoint> nearest = locator.findAll(data);
  double worst = 0.0, squares = 0.0;
  for (const ClosestPoint& c : nearest) {
    worst = std::max(worst, c.distance);
    squares += c.distance * c.distance;
  }
  FitError error{100.0 * worst / diameter, 100.0 * std::sqrt(squares / nearest.size()) / diameter, 0.0};
  if (neighbours) {
    Eigen::VectorXd signedDistances(data.rows());
    for (Eigen::Index i = 0; i < data.rows(); ++i) {
      const ClosestPoint& c = nearest[static_cast<size_t>(i)];
      signedDistances(i) = signedDistance(data.row(i).transpose(), c.position, c.normal);
    }
    error.biasPercent = 100.0 * largestBias(signedDistances, *neighbours) / diameter;
  }
  if (nearestOut) *nearestOut = std::move(nearest);
  return error;
}

std::vector<int> facesFartherThan(const LimitSurface& surface, const std::vector<ClosestPoint>& nearest,
                                  double diameter, double tolerancePercent) {
  std::vector<int> faces;
  for (const ClosestPoint& c : nearest) {
    // The same percentage as a fit's max error.
    if (100.0 * c.distance / diameter > tolerancePercent) faces.push_back(surface.elementControlFace(c.point.element));
  }
  return faces;
}

FitResult fitPointCloud(const MatrixX3& data, const ControlMesh& initial, const FitOptions& options,
                        const ProgressCallback& progress) {
  const auto started = std::chrono::steady_clock::now();
  checkPointCloud(data, "point cloud");
  if (!initial.isClosed()) throw Error("the initial model must be a closed surface (it has boundaries)");
  if (!(options.tolerancePercent > 0.0)) throw Error("the fit tolerance must be > 0 percent");
  if (!(std::isfinite(options.dataStiffness) && options.dataStiffness > 0.0)) {
    throw Error("the data stiffness must be finite and > 0");
  }
  if (!(std::isfinite(options.noise) && options.noise >= 0.0)) {
    throw Error("the data's noise must be finite and >= 0 mm");
  }
  if (!(std::isfinite(options.surfaceSprings) && options.surfaceSprings >= 0.0)) {
    throw Error("the surface springs' stiffness must be finite and >= 0");
  }
  FitResult result;
  result.enclosingSphere = smallestEnclosingSphere(data);
  const double diameter = 2.0 * result.enclosingSphere.radius;
  result.noiseLimited = noiseLimits(data.rows(), options.noise, diameter, options.tolerancePercent);
  const Eigen::MatrixXi neighbours =
      result.noiseLimited ? nearestNeighbours(data, kBiasNeighbours) : Eigen::MatrixXi();
  const auto met = [&](const FitError& e) {
    return e.maxPercent <= options.tolerancePercent ||
           (result.noiseLimited && e.biasPercent <= options.tolerancePercent);
  };
  const double area = LimitSurface::elementCountOf(initial);
  const Eigen::VectorXd stiffness =
      Eigen::VectorXd::Constant(data.rows(), options.dataStiffness * area / static_cast<double>(data.rows()));
  SpringForceModel springs(data, stiffness, SpringForceModel::Attach::NearestEachStep);
  springs.setSamplePerElement(options.springsPerElement);
  std::vector<ForceModel*> forces{&springs};
  std::unique_ptr<SurfaceSprings> surfaceSprings;
  if (options.surfaceSprings > 0.0) {
    surfaceSprings = std::make_unique<SurfaceSprings>(data, options.surfaceSprings * options.dataStiffness);
    forces.push_back(surfaceSprings.get());
  }

  // The springs' lengths are the data's distances where the forces were
  // last evaluated (`points`, whenever the fit is asked before a level's
  // end), measured to the surface points they track, so never shorter than
  // the true distances. When all are within the tolerance, or on noisy data
  // when the bias of their signed lengths is, the fit is measured by a new
  // search and, met, ends there: a level need not reach its equilibrium to
  // be good enough, and the steps on to it would only fit closer than asked
  // (or fit the noise). Where the search says otherwise (the signed
  // lengths' bias is an estimate, and a search can miss), the estimate must
  // fall by a tenth more on this level before it is measured again; the
  // bounds start afresh when the fit is refined.
  double maxBelow = std::numeric_limits<double>::infinity();   // percent
  double biasBelow = std::numeric_limits<double>::infinity();  // percent
  // Local refinement (RefineRegion): the control faces, of the level last
  // measured, that hold a point's nearest surface point farther than the
  // tolerance (grown by kRefineRings rings of faces when refined). Empty:
  // every face.
  std::vector<int> facesToRefine;
  const auto measure = [&](const LimitSurface& surface, const MatrixX3& points) {
    std::vector<ClosestPoint> nearest;
    const FitError e =
        measureFitError(surface, points, data, diameter, result.noiseLimited ? &neighbours : nullptr, &nearest);
    facesToRefine.clear();
    // On noisy data a level is refused by its bias, which no one point's
    // distance locates: refined everywhere.
    if (options.refinesLocally() && !result.noiseLimited) {
      facesToRefine = facesFartherThan(surface, nearest, diameter, options.tolerancePercent);
    }
    return e;
  };
  AcceptFit accept = [&](const LimitSurface& surface, const MatrixX3& points, FitAsk when) {
    // The springs' lengths: every point's, or on a sampled level the
    // sample's, which say only that the fit may be met.
    const Eigen::VectorXd& lengths = springs.lengths();
    const bool everyPoint = lengths.size() == data.rows();
    const double longest =
        lengths.size() > 0 ? 100.0 * lengths.maxCoeff() / diameter : std::numeric_limits<double>::infinity();
    if (when == FitAsk::Step) {
      if (lengths.size() == 0 || options.toEquilibrium) return FitVerdict::Settle;
      const bool maxWithin = longest <= options.tolerancePercent && longest < maxBelow;
      const double bias = result.noiseLimited && !maxWithin && everyPoint
                              ? 100.0 * largestBias(springs.signedLengths(), neighbours) / diameter
                              : std::numeric_limits<double>::infinity();
      const bool biasWithin = bias <= options.tolerancePercent && bias < biasBelow;
      if (!maxWithin && !biasWithin) return FitVerdict::Settle;
      const FitError e = measure(surface, points);
      if (met(e)) {
        result.levelErrors.push_back(e);
        return FitVerdict::Stop;
      }
      if (maxWithin) maxBelow = 0.9 * longest;
      if (biasWithin) biasBelow = 0.9 * bias;
      return FitVerdict::Settle;
    }
    // At the looser rule, springs within the tolerance save a search (unless
    // one at this level already said otherwise): the level goes on to its
    // end, where it is asked again.
    const bool loose = when == FitAsk::LooseRule || when == FitAsk::LastLevelLooseRule;
    if (loose && everyPoint && longest <= options.tolerancePercent && longest < maxBelow) {
      return FitVerdict::Settle;
    }
    const FitError e = measure(surface, points);
    if (e.maxPercent <= options.tolerancePercent) {
      if (when == FitAsk::LevelEnd) result.levelErrors.push_back(e);  // one per level, where it ends
      return FitVerdict::Settle;
    }
    const double closeTo = kRelaxWithin * options.tolerancePercent;
    const bool close = e.maxPercent <= closeTo || (result.noiseLimited && e.biasPercent <= closeTo);
    // Far off on the last level: it goes on to its end, asked (and its
    // error recorded) there.
    if (when == FitAsk::LastLevelLooseRule && !met(e) && !close) return FitVerdict::Settle;
    result.levelErrors.push_back(e);
    // Met by the bias rule (noisy data): stop here, since the steps on to
    // this level's full equilibrium would fit the noise.
    if (met(e)) return FitVerdict::Stop;
    maxBelow = biasBelow = std::numeric_limits<double>::infinity();
    return close ? FitVerdict::Relax : FitVerdict::Refine;
  };

  // The static scheme's progress comes after the accepted trial, the springs'
  // last evaluation: their lengths are the data's distances at that state.
  ProgressCallback progressWithDistances = progress;
  if (progress && options.simulation.integrator.scheme == IntegrationScheme::Static) {
    progressWithDistances = [&](const Progress& p) {
      Progress withDistances = p;
      if (springs.lengths().size() == data.rows()) withDistances.dataDistances = &springs.lengths();
      progress(withDistances);
    };
  }
  RefineRegion region;
  if (options.refinesLocally()) {
    region = [&](const Topology& mesh) { return grownFaces(mesh, facesToRefine, kRefineRings); };
  }
  SimulationResult simulation =
      simulate(initial, forces, {}, options.simulation, accept, progressWithDistances, region);
  result.mesh = std::move(simulation.mesh);
  result.surface = std::move(simulation.surface);
  result.levels = std::move(simulation.levels);
  result.steps = simulation.steps;
  result.error = result.levelErrors.back();
  result.toleranceMet = met(result.error);
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  return result;
}

}  // namespace dynsub
