#include "dynsub/SegmentImage.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <iomanip>
#include <limits>
#include <sstream>

#include "dynsub/ClosestPoint.h"
#include "dynsub/Error.h"
#include "dynsub/FileNames.h"
#include "dynsub/ForceModel.h"
#include "dynsub/ImageFilters.h"
#include "dynsub/Labelmap.h"
#include "dynsub/MeshIO.h"
#include "dynsub/ModelOutputs.h"
#include "dynsub/SelfIntersection.h"
#include "dynsub/ShapeRecovery.h"
#include "dynsub/Trust.h"

namespace dynsub {

namespace {

// "x,y,z[,r]" after a prefix: `count` finite numbers.
std::vector<double> numbersAfter(const std::string& value, std::size_t prefix, int count, const char* expected,
                                 const std::string& option) {
  std::stringstream in(value.substr(prefix));
  std::vector<double> v(count);
  char comma = ',';
  const std::string message = option + " " + value + ": expected " + expected + " (LPS mm)";
  for (int i = 0; i < count; ++i)
    if (!(in >> v[i]) || !std::isfinite(v[i]) || (i + 1 < count && (!(in >> comma) || comma != ',')))
      throw UsageError(message);
  if (in >> comma) throw UsageError(message);
  return v;
}

// Every row of the table with its value, then what the run used in the end:
// whether the slice-end march ran (never from an atlas start, whatever the
// option says), and the edge detector's reference (the image's when there
// were no points on the boundary) and its thresholds.
Report parametersReport(const SegmentParameters& parameters, const SegmentOptions& used, const SegmentResult& result) {
  Report r;
  for (const Parameter& row : segmentParameters()) {
    std::visit(
        [&](const auto& v) {
          using V = std::decay_t<decltype(v)>;
          if constexpr (!std::is_same_v<V, std::monostate>) r.set(row.key(), v);
        },
        parameterValue(parameters, row));
  }
  r.set("slice_ends", used.sliceEnds.enabled);
  if (parameters.segment.edges.method == EdgeMethod::MongaDeriche) {
    const EdgeScale& scale = result.edgeScale;
    r.set("edge_reference", scale.reference == EdgeReference::Landmarks ? "landmarks" : "image");
    r.set("edge_reference_magnitude", scale.magnitude);
    r.set("edge_low", scale.fractions.low);
    r.set("edge_high", scale.fractions.high);
  }
  return r;
}

Report seedReport(const SeedRegion& seed, bool fromLandmarks) {
  Report r;
  r.set("position_lps_mm", seed.click);
  r.set("median", seed.median);
  r.set("spread", seed.spread);
  r.set("intensity_window", std::vector<double>{seed.low, seed.high});
  r.set("window_spreads", seed.window);
  r.set("opening_mm", seed.opening);
  r.set("region_volume_mm3", regionVolume(seed));
  r.set("narrower_window_volume_mm3", seed.narrowerWindowVolume);
  r.set("boundary_points", seed.boundary.size());
  r.set("springs", fromLandmarks ? "landmarks" : "boundary points");
  r.set("leaked", probablyLeaked(seed));
  return r;
}

Report sliceEndsReport(const SliceEnds& ends) {
  std::vector<Report> marched;
  for (const SliceEnd& end : ends.ends) {
    Report r;
    r.set("from_lps_mm", end.marchStart);
    r.set("to_lps_mm", end.end);
    r.set("length_mm", end.length);
    r.set("window", std::vector<double>{end.low, end.high});
    r.set("stopped_by_reach", end.stoppedByReach);
    r.set("marched_again", end.marchedAgain);
    r.set("tapered", end.tapered);
    r.set("pressure", end.pressed);
    if (end.pressed) r.set("pressure_reach_mm", end.pressureReach);
    marched.push_back(r);
  }
  std::vector<Vector3> springPoints;
  for (const Landmark& spring : ends.springs) springPoints.push_back(spring.position);
  Report r;
  r.set("axis", ends.axis);
  r.set("slices", ends.slices);
  r.set("median", ends.median);
  r.set("spread", ends.spread);
  r.set("ends", marched);
  r.set("springs", ends.springs.size());
  r.set("spring_points_lps_mm", springPoints);
  Report pressure;
  pressure.set("n_per_mm2", ends.pressure);
  pressure.set("inside_samples", ends.insideSamples);
  pressure.set("outside_samples", ends.outsideSamples);
  pressure.set("separation", ends.separation);
  r.set("pressure", pressure);
  return r;
}

Report atlasReport(const SegmentInputs& in, const SegmentOutcome& outcome, bool reused) {
  const AtlasAffine& affine = *outcome.atlasAffine;
  const CarriedLabel& carried = *outcome.carried;
  Report r;
  r.set("template", in.atlas->imagePath);
  r.set("labels", in.atlas->labelsPath);
  r.set("label_values", in.atlasLabels);
  Report registration;
  registration.set("affine_metric", affine.metric);
  registration.set("affine_iterations", affine.iterations);
  registration.set("affine_seconds", reused ? 0.0 : affine.seconds);
  registration.set("affine_reused", reused);
  registration.set("deformable_metric", carried.metric);
  registration.set("deformable_iterations", carried.iterations);
  registration.set("deformable_seconds", in.atlasCarried ? 0.0 : carried.seconds);
  registration.set("deformable_reused", in.atlasCarried != nullptr);
  registration.set("largest_warp_mm", carried.largestWarpMm);
  r.set("registration", registration);
  r.set("carried_volume_mm3", carriedVolume(carried));
  if (in.inside) {
    r.set("inside_lps_mm", *in.inside);
    r.set("inside_shift_mm", carried.shift);
  }
  r.set("prior_points", outcome.prior.size());
  r.set("start_elasticity_factor", outcome.atlasStartElasticity);
  r.set("start_crossing_pairs", outcome.atlasStartCrossings);
  return r;
}

// The initial level's control mesh fitted to the carried label's boundary
// points; `elasticity` and `crossings` receive the factor on the fit's
// tension and rigidity it was fitted with, and its triangle pairs that cross.
// With the fit's weak default elasticity, a thin curved structure (a
// caudate's C) folds its concave side through itself, and the segmentation
// keeps the crossing (its labelmap fills the overlap). A start that crosses
// itself is fitted again with stiffer tension and rigidity until one does
// not; failing that, the one that crosses least (Documentation/Segmentation.md,
// "Atlas start").
ControlMesh fitAtlasStart(const std::vector<Landmark>& boundary, double initialFraction, double& elasticity,
                          int& crossings) {
  FitOptions fit;
  fit.simulation.maxLevel = 0;
  // The start is the initial level's surface nearest the carried boundary,
  // not the first one within the fit's tolerance.
  fit.toEquilibrium = true;
  const Material material = fit.simulation.material;
  const MatrixX3 points = landmarkPositions(boundary);
  const ControlMesh initial = initialFromLandmarks(boundary, initialFraction);
  ControlMesh best;
  crossings = std::numeric_limits<int>::max();
  for (const double factor : {1.0, 10.0, 30.0, 100.0}) {
    fit.simulation.material = material.withElasticity(factor);
    FitResult fitted = fitPointCloud(points, initial, fit);
    const int crossing = findSelfIntersections(outputSurface(fitted.mesh, *fitted.surface)).trianglePairs;
    if (crossing < crossings) {
      best = std::move(fitted.mesh);
      elasticity = factor;
      crossings = crossing;
    }
    if (crossing == 0) break;
  }
  return best;
}

// The atlas's start: its structure carried to the image, the prior's points
// on its boundary, and a control mesh fitted to that boundary (the papers'
// cube in its points' PCA ellipsoid, pulled onto 4 times as many points at
// the initial level).
ControlMesh atlasStart(const Volume& image, const SegmentInputs& in, const SegmentParameters& parameters,
                       SegmentOutcome& outcome) {
  outcome.atlasAffine = in.atlasAffine ? in.atlasAffine
                                       : std::make_shared<const AtlasAffine>(
                                             registerAtlasAffine(image, *in.atlas, parameters.registration));
  outcome.carried = in.atlasCarried ? *in.atlasCarried
                                    : carryLabel(image, *in.atlas, in.atlasLabels, *outcome.atlasAffine, in.inside,
                                                 parameters.registration);
  // Farthest-point sampling is greedy: the prior's points are the first of
  // the fit's, spread as evenly as if sampled alone.
  const std::vector<Landmark> boundary = carriedBoundary(*outcome.carried, 4 * parameters.priorPoints);
  const std::size_t priorCount = std::min<std::size_t>(boundary.size(), parameters.priorPoints);
  outcome.prior.assign(boundary.begin(), boundary.begin() + static_cast<std::ptrdiff_t>(priorCount));
  ControlMesh mesh =
      fitAtlasStart(boundary, parameters.initialFraction, outcome.atlasStartElasticity, outcome.atlasStartCrossings);
  // A structure the image's side cuts (the cerebellum at the foot of a
  // scan) gives a fitted surface that bulges past the side: it is shrunk
  // about its centre, 5 % at a time, until its limit surface lies inside.
  const Eigen::RowVector3d centre = mesh.points().colwise().mean();
  const MatrixX3 fitted = mesh.points();
  for (double scale = 1.0; scale > 0.3; scale -= 0.05) {
    mesh.setPoints((fitted.rowwise() - centre) * scale + centre.replicate(fitted.rows(), 1));
    if (limitSurfaceInside(mesh, image.geometry)) return mesh;
  }
  throw Error(in.atlas->labelsPath, "the atlas's structure carried to the image lies mostly outside it");
}

// The initial control mesh, and the springs: the user's landmarks, or for a
// seed start without landmarks the seed region's boundary points, and for an
// atlas start without landmarks the prior's points, softer than an expert's
// clicks.
ControlMesh chooseStart(const Volume& image, const SegmentInputs& in, const SegmentParameters& parameters,
                        SegmentOptions& options, SegmentOutcome& outcome) {
  outcome.springs = in.landmarks;
  switch (in.start.kind) {
    case SegmentStart::Kind::FromLandmarks:
      try {
        return initialFromLandmarks(in.landmarks, parameters.initialFraction);
      } catch (const LandmarkError& error) {
        throw Error(in.landmarkSource, error.what());
      }
    case SegmentStart::Kind::Sphere:
      return initialSphere(in.start.center, in.start.radius);
    case SegmentStart::Kind::Seed: {
      outcome.seed = std::make_unique<SeedRegion>(growFromSeed(image, in.start.center, parameters.seed));
      if (in.landmarks.empty()) {
        outcome.springs = outcome.seed->boundary;
        options.landmarkStiffness = parameters.seed.stiffness;
      }
      return initialFromLandmarks(outcome.seed->boundary, parameters.initialFraction);
    }
    case SegmentStart::Kind::Atlas: {
      ControlMesh mesh = atlasStart(image, in, parameters, outcome);
      // The atlas's structure reaches the ends the march would look for,
      // and its prior holds the surface there. Marching as well, from the
      // clicks or (on thick slices, whose prior points lie on the slices)
      // from the prior's points, lowered Dice on the tuning subjects.
      options.sliceEnds.enabled = false;
      if (in.landmarks.empty()) {
        outcome.springs = outcome.prior;
        options.landmarkStiffness = parameters.priorStiffness;
      }
      return mesh;
    }
    case SegmentStart::Kind::Mesh: {
      ControlMesh mesh = readControlMesh(in.start.meshPath);
      if (!mesh.isClosed()) throw Error(in.start.meshPath, "the initial model must be a closed control mesh");
      requireOutwardFacing(mesh, in.start.meshPath);
      return mesh;
    }
  }
  throw Error("internal: unknown initial model");
}

// Each point's distance to the carried label's boundary (mm): to the
// label from outside, to its complement from inside, at the nearest voxel of
// the label's sub-grid (plus the way there from a point beyond it). A
// label that fills its whole sub-grid has no boundary there: no distances.
std::vector<double> distancesToCarried(const CarriedLabel& label, const std::vector<Vector3>& points) {
  if (points.empty()) return {};
  const Mask& inside = label.mask;
  Mask outside = inside;
  for (std::uint8_t& v : outside.voxels) v = !v;
  const std::vector<float> toInside = distanceTo(inside), toOutside = distanceTo(outside);
  const ImageGeometry& g = inside.geometry;
  std::vector<double> d;
  for (const Vector3& p : points) {
    const Vector3 index = g.toIndex(p);
    std::array<int, 3> v{};
    for (int a = 0; a < 3; ++a) v[a] = std::clamp(static_cast<int>(std::lround(index(a))), 0, g.size[a] - 1);
    const Vector3 centre = g.toPhysical(Vector3(v[0], v[1], v[2]));
    const auto i = static_cast<std::size_t>(g.offset(v[0], v[1], v[2]));
    const double boundary = inside.voxels[i] ? toOutside[i] : toInside[i];
    if (!std::isfinite(boundary)) return {};
    d.push_back((p - centre).norm() + boundary);
  }
  return d;
}

// What the result rests on (Trust.h).
TrustEvidence trustEvidence(const Volume& image, const SegmentInputs& in, const SegmentOutcome& outcome) {
  TrustEvidence e;
  for (const Landmark& l : in.landmarks) e.clicks.push_back(l.position);
  if (outcome.carried) {
    for (const Landmark& l : outcome.prior) e.outline.push_back(l.position);
    e.volume = carriedVolume(*outcome.carried);
    e.clicksToAtlas = distancesToCarried(*outcome.carried, e.clicks);
    if (in.inside) e.insideShift = outcome.carried->shift.norm();
  }
  e.initialVolume = outcome.result.initialVolume;
  e.oneClick = outcome.seed && in.landmarks.empty();
  const SliceEnds& ends = outcome.result.sliceEnds;
  for (const SliceEnd& end : ends.ends)
    if (end.sprung || end.pressed) e.march = std::max(e.march, end.length);
  if (ends.axis >= 0 && !in.landmarks.empty()) {
    e.sliceNormal = image.geometry.direction.col(ends.axis).normalized();
    e.onSlice = kOnSliceVoxels * image.geometry.spacing(ends.axis);
  }
  e.outsideRegion = outcome.result.outsideRegion;
  e.atImageSide = outcome.result.atImageSide;
  e.leakedInImage = outcome.result.leakedInImage;
  return e;
}

Report trustReport(const TrustMeasures& m, const std::vector<TrustFlag>& flags) {
  Report r;
  const auto set = [&r](const char* key, double value) {
    if (std::isfinite(value)) r.set(key, value);
  };
  set("volume_ratio", m.volumeRatio);
  set("initial_volume_ratio", m.initialRatio);
  set("atlas_outline_distance_mm", m.outlineDistance);
  set("clicks_to_atlas_mm", m.clicksToAtlas);
  set("farthest_from_evidence_mm", m.farthestFromEvidence);
  set("march_share", m.marchShare);
  set("inside_shift_mm", m.insideShift);
  std::vector<Report> listed;
  for (const TrustFlag& flag : flags) {
    Report f;
    f.set("name", flag.name);
    f.set("message", flag.message);
    listed.push_back(f);
  }
  r.set("flags", listed);
  r.set("trusted", flags.empty());
  return r;
}

}  // namespace

Report metricsReport(const OverlapMetrics& m) {
  Report r;
  r.set("dice", m.dice);
  r.set("jaccard", m.jaccard);
  r.set("volume_difference_percent", m.volumeDifferencePercent);
  r.set("mean_surface_distance_mm", m.meanSurfaceDistance);
  r.set("hd95_mm", m.hd95);
  r.set("hausdorff_mm", m.hausdorff);
  r.set("volume_mm3", m.volumeA);
  r.set("reference_volume_mm3", m.volumeB);
  return r;
}

SegmentStart parseSegmentStart(const std::string& value, const std::string& option) {
  SegmentStart start;
  start.text = value;
  if (value == "auto") {
    start.kind = SegmentStart::Kind::FromLandmarks;
  } else if (value.rfind("sphere:", 0) == 0) {
    const std::vector<double> v = numbersAfter(value, 7, 4, "sphere:x,y,z,r", option);
    start.kind = SegmentStart::Kind::Sphere;
    start.center = Vector3(v[0], v[1], v[2]);
    start.radius = v[3];
  } else if (value == "atlas") {
    start.kind = SegmentStart::Kind::Atlas;
  } else if (value.rfind("seed:", 0) == 0) {
    const std::vector<double> v = numbersAfter(value, 5, 3, "seed:x,y,z", option);
    start.kind = SegmentStart::Kind::Seed;
    start.center = Vector3(v[0], v[1], v[2]);
  } else {
    start.kind = SegmentStart::Kind::Mesh;
    start.meshPath = value;
  }
  return start;
}

namespace {

// How to make the source say what its values are, for the refusal below.
std::string conventionFix(const std::string& source, CoordinateSystem meant) {
  const std::string system = meant == CoordinateSystem::RAS ? "RAS" : "LPS";
  const std::string extension = lowerCaseExtension(source);
  if (extension == ".json") return "set the markups' \"coordinateSystem\" to \"" + system + "\"";
  if (extension == ".fcsv") return "set the file's header to '# CoordinateSystem = " + system + "'";
  if (extension == ".csv")
    return meant == CoordinateSystem::RAS ? "name the columns r, a, s (a CSV's x, y, z and l, p, s are LPS)"
                                          : "name the columns x, y, z or l, p, s (r, a, s are RAS)";
  return "negate x and y (points given as numbers are LPS)";
}

// Refuses landmarks whose RAS/LPS flip or left-right mirror fits the
// image's edges far better than they do (LandmarkConvention.h), naming the fix.
void refuseMisread(const SegmentInputs& in, const ConventionScores& scores) {
  const Misreading misreading = likelyMisreading(scores);
  if (misreading == Misreading::None) return;
  const ReadingEdges& other = misreading == Misreading::Flipped ? scores.flipped : scores.mirrored;
  std::ostringstream asRead;
  asRead << std::setprecision(3);
  if (scores.asRead.strength > 0)
    asRead << "fit the image's edges far better: median gradient " << other.strength << " against "
           << scores.asRead.strength << " per mm as read, alignment with their shape " << other.alignment
           << " against " << scores.asRead.alignment;
  else
    asRead << "lie on edges (median gradient " << other.strength << " per mm) while, as read, some lie outside the "
           << "image or on none";
  std::ostringstream message;
  if (misreading == Misreading::Flipped) {
    const bool saysRas = in.landmarkSystem == CoordinateSystem::RAS;
    const CoordinateSystem meant = saysRas ? CoordinateSystem::LPS : CoordinateSystem::RAS;
    message << "these points look like " << (saysRas ? "LPS" : "RAS") << "; they are read as "
            << (saysRas ? "RAS" : "LPS") << ". With x and y negated they " << asRead.str() << ". To fix, "
            << conventionFix(in.landmarkSource, meant);
  } else {
    message << "these points look mirrored left to right: with x negated they " << asRead.str()
            << ". Check their x values, and that the image's left and right are stored right";
  }
  message << " (to keep them as read: --check-convention false, or in Slicer 'Skip the convention check')";
  throw Error(in.landmarkSource, message.str());
}

// The evolution's options for these inputs (segmentOptions()).
SegmentOptions optionsFor(const SegmentInputs& in, const SegmentParameters& parameters) {
  const bool pointsOnBoundary = !in.landmarks.empty() || in.start.kind == SegmentStart::Kind::Seed ||
                                in.start.kind == SegmentStart::Kind::Atlas;
  return segmentOptions(parameters, pointsOnBoundary);
}

// The landmarks at distinct positions (to a micrometre): a point clicked
// twice outlines nothing more.
std::size_t distinctPositions(const std::vector<Landmark>& landmarks) {
  std::vector<std::array<long long, 3>> keys;
  for (const Landmark& landmark : landmarks)
    keys.push_back({std::llround(landmark.position.x() * 1e3), std::llround(landmark.position.y() * 1e3),
                    std::llround(landmark.position.z() * 1e3)});
  std::sort(keys.begin(), keys.end());
  return std::unique(keys.begin(), keys.end()) - keys.begin();
}

void checkStart(const SegmentInputs& in) {
  if (in.inside && in.start.kind != SegmentStart::Kind::Atlas)
    throw UsageError(
        "--inside serves an atlas start (--init atlas); to start from one click alone, use --init "
        "seed:x,y,z");
  if (in.start.kind == SegmentStart::Kind::Atlas && (!in.atlas || in.atlasLabels.empty()))
    throw UsageError("an atlas start needs the structure's labels in the atlas (--atlas-label)");
  if (in.start.kind != SegmentStart::Kind::FromLandmarks) return;
  const std::size_t distinct = distinctPositions(in.landmarks);
  if (distinct >= 4) return;
  const std::string alternatives = "give at least 4 on the structure's boundary, or start from one click inside it";
  const std::string none = "no landmarks to build the initial model from: " + alternatives;
  const std::string tooFew =
      std::to_string(in.landmarks.size()) + " landmarks" +
      (distinct < in.landmarks.size() ? ", " + std::to_string(distinct) + " of them at distinct positions," : "") +
      " are too few to outline a structure: " + alternatives;
  // Points given by flags (--seed), or none at all, are the command line's
  // fault: a usage error. A file's are the file's.
  if (in.landmarkSource.empty()) throw UsageError(none);
  if (in.landmarkSource.rfind("--", 0) == 0) throw UsageError(in.landmarkSource, in.landmarks.empty() ? none : tooFew);
  // A file's points that are named but not placed are left out by its reader.
  const std::string unplaced =
      " (points listed but not placed, Slicer's positionStatus undefined or preview or a table's defined 0, are not "
      "counted)";
  throw Error(in.landmarkSource, (in.landmarks.empty() ? none : tooFew) + unplaced);
}

}  // namespace

Vector3 parsePoint(const std::string& text, const std::string& option) {
  const std::vector<double> v = numbersAfter(text, 0, 3, "x,y,z", option);
  return Vector3(v[0], v[1], v[2]);
}

void requireInsideClickInImage(const Volume& image, const SegmentInputs& in) {
  if (in.inside && !(in.inside->allFinite() && image.geometry.covers(*in.inside))) {
    std::ostringstream message;
    message << "the click inside the structure (--inside " << in.inside->x() << "," << in.inside->y() << ","
            << in.inside->z() << ", LPS mm) lies outside the image";
    throw Error(in.image, message.str());
  }
}

void checkSegmentInputs(const SegmentInputs& in, const SegmentParameters& parameters) {
  optionsFor(in, parameters);
  checkStart(in);
}

SegmentOutcome segmentImage(const Volume& image, const SegmentInputs& in, const SegmentParameters& parameters,
                            const ProgressCallback& progress, const std::vector<ForceModel*>& forces) {
  SegmentOptions options = optionsFor(in, parameters);
  checkStart(in);
  requireInsideClickInImage(image, in);

  SegmentOutcome outcome;
  const auto started = std::chrono::steady_clock::now();
  if (in.landmarks.size() >= 4) {
    outcome.convention = conventionScores(image, landmarkPositions(in.landmarks), parameters.segment.edges.sigma,
                                          parameters.segment.edges.landmarkReach);
    if (parameters.checkConvention) refuseMisread(in, *outcome.convention);
  }
  const ControlMesh initial = chooseStart(image, in, parameters, options, outcome);
  const std::vector<Landmark>& springs = outcome.springs;
  // With landmarks, the atlas's prior pulls besides them, softly.
  std::vector<ForceModel*> extraForces = forces;
  std::unique_ptr<SpringForceModel> priorSprings;
  if (outcome.carried && !in.landmarks.empty() && parameters.priorStiffness > 0) {
    const MatrixX3 points = landmarkPositions(outcome.prior);
    priorSprings = std::make_unique<SpringForceModel>(
        points, Eigen::VectorXd::Constant(points.rows(), parameters.priorStiffness),
        SpringForceModel::Attach::NearestEachStep);
    extraForces.push_back(priorSprings.get());
  }

  // The rms landmark distance every 5 steps, the landmarks' nearest points
  // tracked from sample to sample (a new locator only when the level changes).
  TrackedDistances tracked(landmarkPositions(springs));
  const auto rms = [](const Eigen::Ref<const Eigen::VectorXd>& d) {
    return std::sqrt(d.squaredNorm() / static_cast<double>(d.size()));
  };
  ConvergenceRecorder recorder(
      "rms landmark distance (mm)",
      springs.empty() ? ConvergenceRecorder::FitError()
                      : [&](const Progress& p) { return rms(tracked.measure(*p.surface, p.level, *p.controlPoints)); },
      5);
  outcome.result = [&] {
    try {
      return segment(image, springs, initial, options, recorder.callback(progress), extraForces, in.resume.get());
    } catch (const LandmarksOffEdges& error) {
      // Name where the points came from, and the options that help.
      throw Error(in.landmarkSource, std::string(error.what()) + " (--edge-landmark-reach, --edge-reference image)");
    } catch (const LandmarkError& error) {
      throw Error(in.landmarkSource, error.what());
    }
  }();
  const auto voxelizing = std::chrono::steady_clock::now();
  const ImageGeometry& grid = in.labelmapGrid ? *in.labelmapGrid : image.geometry;
  outcome.labelmap = labelmapOf(outcome.result.surface, grid);
  // An empty labelmap is no segmentation, whatever the measures of trust say
  // of a surface that small.
  if (outcome.labelmap.count() == 0)
    throw Error(in.landmarkSource.empty() ? in.image : in.landmarkSource,
                "the result encloses no voxel of the image: the surface shrank below a voxel (landmarks spread "
                "across the structure, or a click inside it, give it room)");
  const auto finished = std::chrono::steady_clock::now();
  outcome.seconds = std::chrono::duration<double>(finished - started).count();
  outcome.history = recorder.history();
  // The chart ends on the landmarks' distances where the last level ended.
  const std::vector<double>& ends = outcome.result.landmarkDistances;
  if (!ends.empty() && !outcome.result.levels.empty())
    outcome.history.setLevelEndError(
        outcome.result.levels.back().level,
        rms(Eigen::Map<const Eigen::VectorXd>(ends.data(), static_cast<Eigen::Index>(ends.size()))));
  const SegmentResult& result = outcome.result;
  outcome.warnings = result.warnings;
  if (outcome.carried && in.landmarks.empty()) {
    // The springs are the atlas's boundary points, not clicks: segment()'s
    // warning of clicks far from edges says here where atlas and image disagree.
    outcome.warnings.erase(std::remove_if(outcome.warnings.begin(), outcome.warnings.end(),
                                          [](const std::string& w) { return w.rfind("landmark", 0) == 0; }),
                           outcome.warnings.end());
    const double range = options.edges.captureRange;
    const auto far = std::count_if(result.landmarkEdgeDistances.begin(), result.landmarkEdgeDistances.end(),
                                   [range](double d) { return d > range; });
    if (far > 0) {
      std::ostringstream warning;
      warning << far << " of the atlas's " << springs.size() << " boundary points are more than " << range
              << " mm from every edge the image shows: the atlas and the image disagree there (check the "
                 "result, or add clicks)";
      outcome.warnings.push_back(warning.str());
    }
  }
  if (outcome.seed) {
    const std::vector<std::string> seed = seedWarnings(*outcome.seed);
    outcome.warnings.insert(outcome.warnings.begin(), seed.begin(), seed.end());
  }
  const Report crossing = selfIntersectionReport(result.surface, "LPS", outcome.warnings);
  const TrustEvidence evidence = trustEvidence(image, in, outcome);
  outcome.trust = measureTrust(result.surface, result.volume, evidence);
  outcome.trustFlags = trustFlags(outcome.trust, evidence);

  Report& report = outcome.report;
  report.set("image", in.image);
  report.set("landmarks", in.landmarkSource);
  report.set("landmark_count", in.landmarks.size());
  report.set("init", in.start.text);
  if (outcome.convention) {
    Report convention;
    const auto reading = [](const ReadingEdges& edges) {
      Report r;
      r.set("strength", edges.strength);
      r.set("alignment", edges.alignment);
      return r;
    };
    convention.set("as_read", reading(outcome.convention->asRead));
    convention.set("flipped", reading(outcome.convention->flipped));
    convention.set("mirrored", reading(outcome.convention->mirrored));
    convention.set("flipped_evidence", misreadingEvidence(*outcome.convention, Misreading::Flipped));
    convention.set("mirrored_evidence", misreadingEvidence(*outcome.convention, Misreading::Mirrored));
    report.set("landmark_edges", convention);
  }
  if (outcome.seed) report.set("seed", seedReport(*outcome.seed, !in.landmarks.empty()));
  if (outcome.carried) report.set("atlas", atlasReport(in, outcome, in.atlasAffine != nullptr));
  if (in.reference) {
    outcome.metrics = compareMasks(outcome.labelmap, in.reference());
    report.set("reference", in.referencePath);
    report.set("reference_labels", in.referenceLabels);
    report.merge(metricsReport(outcome.metrics));
  } else {
    report.set("volume_mm3", outcome.labelmap.count() * grid.spacing.prod());
  }
  report.set("control_vertices", result.mesh.vertexCount());
  report.set("levels", result.levels.back().level);
  report.set("iterations", result.steps);
  report.set("final_energy", result.levels.back().energy);
  report.set("seconds", outcome.seconds);
  Report stages;
  stages.set("crop", result.seconds.crop);
  stages.set("edge_potential", result.seconds.potential);
  stages.set("evolution", result.seconds.evolution);
  stages.set("voxelize", std::chrono::duration<double>(finished - voxelizing).count());
  report.set("stage_seconds", stages);
  if (options.sliceEnds.enabled) report.set("slice_ends", sliceEndsReport(result.sliceEnds));
  Report region;
  region.set("first_voxel", result.regionFirst);
  region.set("size_voxels", result.regionSize);
  report.set("region_of_interest", region);
  report.set("initial_volume_mm3", result.initialVolume);
  report.set("surface_volume_mm3", result.volume);
  report.set("surface_outside_region", result.outsideRegion);
  report.set("surface_at_image_side", result.atImageSide);
  if (std::isfinite(result.surfaceOnEdges)) report.set("surface_on_edges", result.surfaceOnEdges);
  report.set("self_intersection", crossing);
  report.set("warnings", outcome.warnings);
  report.set("trust", trustReport(outcome.trust, outcome.trustFlags));
  std::vector<Report> residuals;
  for (std::size_t i = 0; i < springs.size(); ++i) {
    Report r;
    r.set("label", springs[i].label);
    r.set("position_lps_mm", springs[i].position);
    r.set("distance_mm", result.landmarkDistances[i]);
    if (i < result.landmarkEdgeDistances.size() && std::isfinite(result.landmarkEdgeDistances[i]))
      r.set("edge_distance_mm", result.landmarkEdgeDistances[i]);
    residuals.push_back(r);
  }
  report.set("landmark_residuals", residuals);
  std::vector<Report> levels;
  for (const auto& level : result.levels) levels.push_back(levelReport(level, -1, -1));  // no fit error in segmentation
  report.set("per_level", levels);
  report.set("parameters", parametersReport(parameters, options, result));
  return outcome;
}

std::string carriedPastSlices(const SegmentResult& result) {
  std::ostringstream out;
  out << std::fixed << std::setprecision(1);
  bool first = true;
  for (const SliceEnd& end : result.sliceEnds.ends) {
    // Only ends beyond which something acted: a spring where the march
    // stopped (SliceEnds.h, step 4) or the pressure (step 5).
    if (!end.pressed && !end.sprung) continue;
    out << (first ? "" : ", ") << end.length << " mm " << (end.side < 0 ? "before the first" : "after the last")
        << (end.stoppedByReach ? " (no end seen)" : "");
    first = false;
  }
  return out.str();
}

}  // namespace dynsub
