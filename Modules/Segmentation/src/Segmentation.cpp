#include "dynsub/Segmentation.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <future>
#include <iomanip>
#include <memory>
#include <optional>
#include <sstream>
#include <tuple>

#include "RobustStatistics.h"
#include "dynsub/ApplyOperator.h"
#include "dynsub/ClickAppearance.h"
#include "dynsub/ClosestPoint.h"
#include "EdgeForce.h"
#include "dynsub/Error.h"
#include "dynsub/Forces.h"
#include "dynsub/InitialModels.h"
#include "dynsub/ParallelFor.h"
#include "dynsub/Tessellation.h"

namespace dynsub {
namespace {

using Clock = std::chrono::steady_clock;

double secondsSince(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

// The gated region pressure (SegmentOptions::regionPressure).
class RegionPressureForceModel final : public ForceModel {
 public:
  RegionPressureForceModel(const Volume& image, double median, double spread, double strength, double window)
      : image_(image), toIndex_(image.geometry.indexFromPhysical()), median_(median),
        width_(window * std::max(spread, 1e-6)), strength_(strength),
        slope_(std::abs(strength) / width_ * steepGradient(image)) {}
  void beginLevel(const LimitSurface&, const SurfaceQuadrature& quadrature, const MatrixX3&) override {
    quadrature_ = &quadrature;
  }
  MatrixX3 generalizedForce(const MatrixX3& controlPoints, double&) override {
    const MatrixX3 positions = applyOperator(quadrature_->J, controlPoints);
    Eigen::VectorXd pressures(positions.rows());
    for (Eigen::Index i = 0; i < positions.rows(); ++i) {
      const Vector3 index = toIndex_ * (positions.row(i).transpose() - image_.geometry.origin);
      // Outside the region the image is unknown (interpolate would repeat its border): no push.
      const double gate =
          image_.geometry.spans(index) ? 1.0 - std::abs(image_.interpolate(index) - median_) / width_ : 0.0;
      pressures(i) = strength_ * std::clamp(gate, -1.0, 1.0);
    }
    return pressureForces(*quadrature_, controlPoints, pressures);
  }
  // The gate changes by 1 / width_ per unit of intensity, and the intensity
  // at most by about the steep gradient per mm: without this slope in the
  // stabilizer, the pressure overshoots at long time steps (the ball that
  // SegmentationUnitTest grows from a 3 mm seed would collapse at 4 s).
  SparseMatrix stabilizingStiffness(const MatrixX3& controlPoints) override {
    return fieldStiffness(*quadrature_, controlPoints, slope_);
  }

 private:
  const Volume& image_;
  Matrix3 toIndex_;
  double median_, width_, strength_, slope_;
  const SurfaceQuadrature* quadrature_ = nullptr;
};

MatrixX3 limitPoints(const ControlMesh& mesh, int segments) {
  const LimitSurface surface(mesh);
  return tessellate(surface, mesh.points(), segments).points;
}

// The volume a closed, consistently oriented triangle surface encloses (mm^3):
// the divergence theorem, a signed tetrahedron per triangle.
double enclosedVolume(const TriangleSurface& s) {
  double six = 0;
  for (const auto& t : s.triangles)
    six += s.points.row(t[0]).dot(s.points.row(t[1]).cross(s.points.row(t[2])));
  return std::abs(six) / 6.0;
}

// The pressure beyond the end slices (ClickAppearance.h), filling its part
// of `ends`. It acts beyond an end unless that end's march found the
// structure ending within `gap` of the outermost slice (an end the clicks
// already reach, as the bundled caudate's do); none at all
// when off, when the clicks are not on slices, or when they gave too few
// samples. It reaches as far along the axis as the region was asked to, and
// beyond a tapering end (SliceEnds.h, step 4) only as far as its march went:
// there the spring holds the end the march saw, and a pressure past it grows
// the end on into like tissue (a putamen's lower end into the grey matter
// below it).
std::optional<EndPressure> endPressure(const SegmentationRegion& region, const std::vector<Landmark>& landmarks,
                                       const SliceEndOptions& options, SliceEnds& ends) {
  if (ends.axis < 0 || !(options.pressure > 0)) return std::nullopt;
  std::optional<EndPressure::End> beyond[2];  // before and after the clicked span, along the axis
  const auto [low, high] = region.spanAlong(ends.axis);
  const Vector3 along = region.image().geometry.direction.col(ends.axis).normalized();
  for (const SliceEnd& end : ends.ends)
    if (end.stoppedByReach || end.length > options.gap) {
      const double slice = along.dot(end.start);
      double reach = end.side > 0 ? high - slice : slice - low;
      // A tapering end's march saw where it ends: no farther.
      if (end.tapered) reach = std::min(reach, end.length);
      beyond[end.side > 0] = EndPressure::End{end.start, end.sliceRadius, reach};
    }
  if (!beyond[0] && !beyond[1]) return std::nullopt;
  std::optional<ClickAppearance> appearance = ClickAppearance::learn(region.image(), landmarks, ends.axis);
  if (!appearance) return std::nullopt;
  for (SliceEnd& end : ends.ends) {
    end.pressed = beyond[end.side > 0].has_value();
    if (end.pressed) end.pressureReach = beyond[end.side > 0]->reach;
  }
  ends.pressure = options.pressure;
  ends.insideSamples = appearance->insideSamples();
  ends.outsideSamples = appearance->outsideSamples();
  ends.separation = appearance->separation();
  return std::optional<EndPressure>(std::in_place, region.image(), std::move(*appearance), landmarks, ends.axis,
                                    options.pressure, beyond[0], beyond[1]);
}

}  // namespace

SimulationOptions SegmentOptions::defaultSimulation() {
  SimulationOptions o;
  o.maxLevel = 1;  // the papers' 98 -> 386 control vertices
  o.elasticityPerLevel = 0.25;
  // Shorter steps let a level creep on to the step limit; from 4 s on the
  // forces' stabilizing stiffness (Integrator.h) outweighs the damping and
  // longer steps give the same results (the evaluation plan's tuning split,
  // Documentation/Segmentation.md, "The time step").
  o.integrator.timeStep = 4.0;
  // 386 control vertices: the refined level's tables are built on the
  // second core while the first level runs on one.
  o.prepareNextLevel = true;
  return o;
}

void checkSegmentOptions(const SegmentOptions& options) {
  checkEdgeOptions(options.edges);
  requireFiniteNonNegative(options.imageForce, "image force");
  // A spring of stiffness 0 pulls nothing: landmarks would be read and ignored.
  if (!(options.landmarkStiffness > 0) || !std::isfinite(options.landmarkStiffness))
    throw Error("the landmark stiffness must be a finite number > 0, got " + std::to_string(options.landmarkStiffness));
  requireFiniteNonNegative(options.landmarkDeadZone, "landmark dead zone");
  checkSliceEndOptions(options.sliceEnds);
  requireFiniteNonNegative(options.margin, "margin");
  requireFiniteNonNegative(options.landmarkTolerance, "landmark tolerance");
  if (!std::isfinite(options.inflation)) throw Error("inflation must be finite");
  if (!std::isfinite(options.regionPressure)) throw Error("the region pressure must be finite");
  if (!(options.regionWindow > 0) || !std::isfinite(options.regionWindow))
    throw Error("the region window must be a finite number > 0");
  checkSimulationOptions(options.simulation);
}

ControlMesh initialFromLandmarks(const std::vector<Landmark>& landmarks, double fraction) {
  const MatrixX3 points = landmarkPositions(landmarks);
  // Clicks on one slice are the flat set users give; say what would do.
  // (Points on a line, or at one point, get checkPointCloud's own words.)
  // One slice of clicks says nothing of the structure across the slice:
  // even with a seed click at their centre the surface collapses or leaks, so
  // such landmarks are refused rather than guessed at.
  if (points.rows() >= 4 && points.allFinite() && spannedDimensions(points) == 2)
    throw LandmarkError("all " + std::to_string(points.rows()) +
                        " landmarks lie on one plane, as clicks on a single slice do: a surface needs the boundary "
                        "clicked on at least two slices across the structure, or one click inside it "
                        "(--init seed:x,y,z)");
  try {
    checkPointCloud(points, "the landmarks");
  } catch (const Error& error) {
    throw LandmarkError(error.what());  // the caller names the file
  }
  return initialModel(points, InitialShape::Sphere, fraction);
}

std::vector<double> distancesToSurface(const LimitSurface& surface, const MatrixX3& controlPoints,
                                       const MatrixX3& landmarkPoints) {
  ClosestPointLocator locator(surface);
  locator.update(controlPoints);
  std::vector<double> distances;
  for (const auto& closest : locator.findAll(landmarkPoints)) distances.push_back(closest.distance);
  return distances;
}

bool limitSurfaceInside(const ControlMesh& mesh, const ImageGeometry& grid) {
  const MatrixX3 points = limitPoints(mesh, 2);
  for (Eigen::Index p = 0; p < points.rows(); ++p)
    if (!grid.covers(points.row(p).transpose())) return false;
  return true;
}

void requireLandmarksInside(const ImageGeometry& grid, const std::vector<Landmark>& landmarks) {
  for (std::size_t i = 0; i < landmarks.size(); ++i)
    if (!grid.covers(landmarks[i].position)) {
      const Vector3& p = landmarks[i].position;
      std::ostringstream message;
      message << "landmark " << i + 1 << " of " << landmarks.size()
              << (landmarks[i].label.empty() ? "" : " ('" + landmarks[i].label + "')") << " at (" << p.x() << ", "
              << p.y() << ", " << p.z() << ") mm LPS lies outside the image";
      throw LandmarkError(message.str());
    }
}

SegmentationRegion::SegmentationRegion(const Volume& image, const std::vector<Landmark>& landmarks,
                                       const ControlMesh& initial, const SegmentOptions& options,
                                       const std::vector<Landmark>& alsoCover) {
  checkSegmentOptions(options);
  if (!initial.isClosed()) throw Error("the initial model must be a closed control mesh");
  const ImageGeometry& grid = image.geometry;
  wholeImage_ = grid;
  requireLandmarksInside(grid, landmarks);
  if (!limitSurfaceInside(initial, grid)) throw Error("the initial model reaches outside the image");
  const MatrixX3 start = limitPoints(initial, 2);

  auto clock = Clock::now();
  const MatrixX3 landmarkPoints = landmarkPositions(landmarks);
  const MatrixX3 coverPoints = landmarkPositions(alsoCover);
  MatrixX3 extent(start.rows() + landmarkPoints.rows() + coverPoints.rows(), 3);
  extent << start, landmarkPoints, coverPoints;
  std::tie(first_, size_) = boundingRegion(grid, extent, options.margin);
  for (int a = 0; a < 3; ++a) {
    const Eigen::VectorXd t = extent * grid.direction.col(a).normalized();
    span_[a] = {t.minCoeff() - options.margin, t.maxCoeff() + options.margin};
  }
  image_ = cropVolume(image, first_, size_);
  // readVolume refuses such images; a volume made in memory is checked here,
  // on the region the forces come from.
  if (!std::all_of(image_.voxels.begin(), image_.voxels.end(), [](float v) { return std::isfinite(v); }))
    throw Error("the image has voxels that are NaN or infinite in the segmentation's region");
  const Volume& region = image_;
  geometry_ = region.geometry;
  cropSeconds_ = secondsSince(clock);
  clock = Clock::now();
  edgeField_ = std::make_unique<const EdgeField>(region, options.edges, landmarkPoints);
  potentialSeconds_ = secondsSince(clock);
}

bool SegmentationRegion::covers(const MatrixX3& points) const {
  for (Eigen::Index p = 0; p < points.rows(); ++p)
    if (!covers(Vector3(points.row(p).transpose()))) return false;
  return true;
}

bool SegmentationRegion::covers(const Vector3& point) const { return geometry_.covers(point); }

SegmentResult evolveInRegion(const SegmentationRegion& region, const std::vector<Landmark>& landmarks,
                             const ControlMesh& initial, const LevelOrigin& origin, const SegmentOptions& options,
                             const ProgressCallback& progress, const std::vector<ForceModel*>& extraForces,
                             const PressureField* pressure) {
  checkSegmentOptions(options);
  if (!initial.isClosed()) throw Error("the initial model must be a closed control mesh");
  const auto clock = Clock::now();
  const MatrixX3 landmarkPoints = landmarkPositions(landmarks);
  // The limit surface, not the control points: those of a mesh fitted to a
  // shape (an atlas start) lie outside it, and may lie outside the image.
  if (!region.covers(landmarkPoints) || !region.covers(limitPoints(initial, 2)))
    throw Error("the landmarks or the initial model reach outside the region of interest: build a new region");
  const EdgeForce field(region.edgeField(), options.imageForce);
  FieldForceModel imageForces(field, pressure);
  Eigen::VectorXd stiffness = Eigen::VectorXd::Constant(landmarkPoints.rows(), options.landmarkStiffness);
  SpringForceModel springs(landmarkPoints, stiffness, SpringForceModel::Attach::NearestEachStep);
  springs.setDeadZone(options.landmarkDeadZone);
  InflationForceModel inflation(options.inflation);
  std::unique_ptr<RegionPressureForceModel> regionPressure;
  if (options.regionPressure != 0) {
    const std::optional<RobustStatistics> inside = insideIntensities(region.image(), initial);
    if (!inside) throw Error("the initial model encloses no voxel of the region: no appearance to learn");
    regionPressure = std::make_unique<RegionPressureForceModel>(region.image(), inside->median, inside->spread,
                                                                options.regionPressure, options.regionWindow);
  }
  std::vector<ForceModel*> forces = {&imageForces};
  if (regionPressure) forces.push_back(regionPressure.get());
  if (landmarkPoints.rows() > 0 && options.landmarkStiffness > 0) forces.push_back(&springs);
  if (options.inflation != 0) forces.push_back(&inflation);
  forces.insert(forces.end(), extraForces.begin(), extraForces.end());
  // Refine while a landmark is farther than the tolerance (see the header).
  // The last level's distances are the result's.
  std::vector<double> distances;
  auto landmarksFit = [&](const LimitSurface& surface, const MatrixX3& controlPoints, FitAsk when) {
    // Landmarks are measured where a level ends, not after every step.
    if (when == FitAsk::Step) return FitVerdict::Settle;
    if (landmarkPoints.rows() == 0) return FitVerdict::Refine;
    distances = distancesToSurface(surface, controlPoints, landmarkPoints);
    for (double distance : distances)
      if (distance > options.landmarkTolerance) return FitVerdict::Refine;
    return FitVerdict::Settle;
  };
  SimulationOptions simulation = options.simulation;
  simulation.origin = origin;
  SimulationResult evolved = simulate(initial, forces, {}, simulation, landmarksFit, progress);

  SegmentResult result;
  result.mesh = std::move(evolved.mesh);
  result.levels = std::move(evolved.levels);
  result.steps = evolved.steps;
  result.origin = evolved.origin;
  result.limit = std::move(evolved.surface);
  result.regionFirst = region.first();
  result.regionSize = region.size();
  result.edgeScale = region.edgeField().scale();
  result.seconds.crop = region.cropSeconds();
  result.seconds.potential = region.potentialSeconds();
  result.seconds.evolution = secondsSince(clock);
  result.landmarkDistances = std::move(distances);  // simulate() asks landmarksFit at every level's end
  return result;
}

SegmentResult segment(const Volume& image, const std::vector<Landmark>& landmarks, const ControlMesh& initial,
                      const SegmentOptions& options, const ProgressCallback& progress,
                      const std::vector<ForceModel*>& extraForces, const SegmentResult* resume) {
  // Soft springs at the structure's ends beyond the clicked slices (SliceEnds.h).
  SliceEnds ends;
  if (options.sliceEnds.enabled) ends = findSliceEnds(image, landmarks, initial, options.sliceEnds);
  const SegmentationRegion region(image, landmarks, initial, options, ends.springs);
  const MatrixX3 endPoints = landmarkPositions(ends.springs);
  SpringForceModel endSprings(endPoints, Eigen::VectorXd::Constant(endPoints.rows(), options.sliceEnds.stiffness),
                              SpringForceModel::Attach::NearestEachStep);
  std::vector<ForceModel*> forces = extraForces;
  if (endPoints.rows() > 0) forces.push_back(&endSprings);
  std::optional<EndPressure> pressure = endPressure(region, landmarks, options.sliceEnds, ends);
  // The initial model's volume (for the collapse check) is measured on
  // the second core while the evolution runs on one.
  std::future<double> initialVolume = std::async(std::launch::async, [&initial] {
    const LimitSurface limit(initial);
    return enclosedVolume(tessellate(limit, initial.points(), outputSegments(limit)));
  });
  // The earlier result's own limit surface (its topology's tables) serves the check.
  const bool resumes = resume && region.covers(tessellate(*resume->limit, resume->mesh.points(), 2).points);
  SegmentResult result =
      evolveInRegion(region, landmarks, resumes ? resume->mesh : initial, resumes ? resume->origin : LevelOrigin{},
                     options, progress, forces, pressure ? &*pressure : nullptr);
  result.sliceEnds = std::move(ends);

  if (!result.mesh.points().allFinite()) throw Error("the evolution produced a non-finite surface");
  const LimitSurface& limit = *result.limit;
  result.surface = tessellate(limit, result.mesh.points(), outputSegments(limit));
  const TriangleSurface& triangles = result.surface;
  result.initialVolume = initialVolume.get();
  result.volume = enclosedVolume(triangles);
  Eigen::Index outside = 0, atSide = 0, leaked = 0;
  const ImageGeometry& whole = region.wholeImage();
  const Eigen::Array3d sideAt = Eigen::Array3d(whole.size[0], whole.size[1], whole.size[2]) - 1.5;
  for (Eigen::Index p = 0; p < triangles.points.rows(); ++p) {
    const Vector3 point = triangles.points.row(p).transpose();
    const Eigen::Array3d index = whole.toIndex(point).array();
    const bool out = !region.covers(point), side = (index < 0.5).any() || (index > sideAt).any();
    outside += out;
    atSide += side;
    leaked += out && !side;
  }
  const double points = static_cast<double>(std::max<Eigen::Index>(triangles.points.rows(), 1));
  result.outsideRegion = static_cast<double>(outside) / points;
  result.atImageSide = static_cast<double>(atSide) / points;
  result.leakedInImage = static_cast<double>(leaked) / points;
  std::ostringstream warning;
  warning << std::fixed << std::setprecision(0);
  const bool collapsed = result.volume < kCollapsedBelow * result.initialVolume;
  if (collapsed) {
    warning << "the surface shrank to " << 100 * result.volume / result.initialVolume
            << " % of the initial model's volume: it has probably collapsed (give more landmarks, or start "
               "closer to the structure's boundary)";
    result.warnings.push_back(warning.str());
    warning.str("");
  }
  if (options.edges.method == EdgeMethod::MongaDeriche) {
    const EdgeField& field = region.edgeField();
    const double voxel = region.image().geometry.spacing.maxCoeff();
    Eigen::Index held = 0;
    result.surfaceEdgeDistances.resize(triangles.points.rows());
    for (Eigen::Index p = 0; p < triangles.points.rows(); ++p) {
      const double d = field.edgeDistance(Vector3(triangles.points.row(p).transpose()));
      held += d <= voxel;
      result.surfaceEdgeDistances(p) = std::isfinite(d) ? d : -1.0;
    }
    result.surfaceOnEdges = static_cast<double>(held) / std::max<Eigen::Index>(triangles.points.rows(), 1);
    // One warning naming every landmark beyond the capture range.
    std::string far;
    int farCount = 0;
    for (std::size_t i = 0; i < landmarks.size(); ++i) {
      const double d = field.edgeDistance(landmarks[i].position);
      result.landmarkEdgeDistances.push_back(d);
      if (d > options.edges.captureRange) {
        far += (far.empty() ? "" : ", ") + std::to_string(i + 1) +
               (landmarks[i].label.empty() ? "" : " ('" + landmarks[i].label + "')");
        ++farCount;
      }
    }
    if (farCount > 0) {
      warning << std::setprecision(1) << (farCount == 1 ? "landmark " : "landmarks ") << far
              << (farCount == 1 ? " is" : " are") << " more than " << options.edges.captureRange
              << " mm from every edge the image shows: a click off the boundary? It pulls the surface there"
              << std::setprecision(0);
      result.warnings.push_back(warning.str());
      warning.str("");
    }
  }
  // At the image's side, raising the margin cannot help: the scan ends there.
  if (result.atImageSide > kAtImageSideAbove) {
    warning << std::setprecision(1) << 100 * result.atImageSide
            << " % of the surface lies at the image's side or beyond it: the structure probably continues past "
               "the scan's field of view, and its labelmap stops at the image's side (or the surface leaked there: "
               "add landmarks where it ends)"
            << std::setprecision(0);
    result.warnings.push_back(warning.str());
    warning.str("");
  }
  if (result.leakedInImage > kLeakedAbove) {
    warning << 100 * result.leakedInImage
            << " % of the surface left the region of interest, where no image force holds it: it has "
               "probably leaked (add landmarks where it escaped, or raise --margin)";
    result.warnings.push_back(warning.str());
    warning.str("");
  }
  // A surface still moving when the steps ran out is where it happened to
  // be, not where the forces balance. (A collapsing one is said above: more
  // steps would not help it.)
  if (!collapsed && !result.levels.empty() && !result.levels.back().converged) {
    warning << "the surface was still moving when the last level reached its step limit of "
            << options.simulation.equilibrium.maxSteps
            << " steps (max_steps, --max-steps): check the result, or raise the limit";
    result.warnings.push_back(warning.str());
  }
  return result;
}

}  // namespace dynsub
