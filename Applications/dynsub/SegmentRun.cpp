#include "SegmentRun.h"

#include <chrono>
#include <cmath>
#include <sstream>

#include "FigureOutputs.h"
#include "Reporting.h"
#include "dynsub/ClosestPoint.h"
#include "dynsub/Error.h"
#include "dynsub/MeshIO.h"

namespace dynsub::app {

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
      throw Error(message);
  if (in >> comma) throw Error(message);
  return v;
}

nlohmann::ordered_json metricsJson(const OverlapMetrics& m) {
  return {{"dice", m.dice},
          {"jaccard", m.jaccard},
          {"volume_difference_percent", m.volumeDifferencePercent},
          {"mean_surface_distance_mm", m.meanSurfaceDistance},
          {"hd95_mm", m.hd95},
          {"hausdorff_mm", m.hausdorff},
          {"volume_mm3", m.volumeA},
          {"reference_volume_mm3", m.volumeB}};
}

const char* referenceName(EdgeReference reference) {
  return reference == EdgeReference::Landmarks ? "landmarks" : "image";
}

// The initial control mesh, and the springs: the user's landmarks, or for a
// seed start without landmarks the seed region's boundary points, softer than
// an expert's clicks.
ControlMesh chooseStart(const Volume& image, SegmentInputs& in, SegmentRun& run) {
  run.springs = in.landmarks;
  switch (in.init.kind) {
    case InitialModel::Kind::FromLandmarks:
      if (in.landmarks.size() < 4)
        throw Error("the initial model is built from the landmarks: give at least 4, or start from a seed "
                    "click inside the structure, a sphere or a control mesh");
      return initialFromLandmarks(in.landmarks);
    case InitialModel::Kind::Sphere:
      return initialSphere(in.init.center, in.init.radius);
    case InitialModel::Kind::Seed: {
      run.seed = std::make_unique<SeedRegion>(growFromSeed(image, in.init.center, in.seed));
      if (in.landmarks.empty()) {
        run.springs = run.seed->boundary;
        in.segment.landmarkStiffness = in.seed.stiffness;
      }
      return initialFromLandmarks(run.seed->boundary);
    }
    case InitialModel::Kind::Mesh: {
      ControlMesh mesh = readControlMesh(in.init.meshPath);
      if (!mesh.isClosed()) throw Error(in.init.meshPath, "the initial model must be a closed control mesh");
      return mesh;
    }
  }
  throw Error("internal: unknown initial model");
}

}  // namespace

InitialModel parseInitialModel(const std::string& value, const std::string& option) {
  InitialModel init;
  init.text = value;
  if (value == "auto") {
    init.kind = InitialModel::Kind::FromLandmarks;
  } else if (value.rfind("sphere:", 0) == 0) {
    const std::vector<double> v = numbersAfter(value, 7, 4, "sphere:x,y,z,r", option);
    init.kind = InitialModel::Kind::Sphere;
    init.center = Vector3(v[0], v[1], v[2]);
    init.radius = v[3];
  } else if (value.rfind("seed:", 0) == 0) {
    const std::vector<double> v = numbersAfter(value, 5, 3, "seed:x,y,z", option);
    init.kind = InitialModel::Kind::Seed;
    init.center = Vector3(v[0], v[1], v[2]);
  } else {
    init.kind = InitialModel::Kind::Mesh;
    init.meshPath = value;
  }
  return init;
}

SegmentRun runSegmentation(const Volume& image, SegmentInputs in, const ProgressCallback& progress) {
  SegmentRun run;
  const ControlMesh initial = chooseStart(image, in, run);
  const std::vector<Landmark>& springs = run.springs;

  const auto started = std::chrono::steady_clock::now();
  // The rms landmark distance every 5 steps, the landmarks' nearest points
  // tracked from sample to sample (a new locator only when the level changes).
  TrackedDistances tracked(landmarkPositions(springs));
  ConvergenceRecorder recorder(
      "rms landmark distance (mm)",
      springs.empty() ? ConvergenceRecorder::FitError()
                      : [&](const Progress& p) {
                          const Eigen::VectorXd d = tracked.measure(*p.surface, p.level, *p.controlPoints);
                          return std::sqrt(d.squaredNorm() / static_cast<double>(d.size()));
                        },
      5);
  run.result = [&] {
    try {
      return segment(image, springs, initial, in.segment, recorder.callback(progress));
    } catch (const LandmarksOffEdges& error) {
      // Name where the points came from, and the options that help.
      throw Error(in.landmarkSource, std::string(error.what()) + " (--edge-landmark-reach, --edge-reference image)");
    } catch (const LandmarkError& error) {
      throw Error(in.landmarkSource, error.what());
    }
  }();
  run.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  run.history = recorder.history();
  const SegmentResult& result = run.result;

  nlohmann::ordered_json& report = run.report;
  report["image"] = in.image;
  report["landmarks"] = in.landmarkSource;
  report["landmark_count"] = in.landmarks.size();
  report["init"] = in.init.text;
  if (const SeedRegion* seed = run.seed.get()) {
    report["seed"] = {{"position_lps_mm", {seed->click.x(), seed->click.y(), seed->click.z()}},
                      {"median", seed->median},
                      {"spread", seed->spread},
                      {"intensity_window", {seed->low, seed->high}},
                      {"window_spreads", seed->window},
                      {"opening_mm", seed->opening},
                      {"region_volume_mm3", seed->mask.count() * seed->mask.geometry.spacing.prod()},
                      {"boundary_points", seed->boundary.size()},
                      {"springs", in.landmarks.empty() ? "boundary points" : "landmarks"},
                      {"leaked", seed->touchesReach}};
  }
  if (in.reference) {
    run.metrics = compareMasks(result.labelmap, *in.reference);
    report["reference"] = in.referencePath;
    report["reference_labels"] = in.referenceLabels;
    const nlohmann::ordered_json measured = metricsJson(run.metrics);
    for (const auto& [key, value] : measured.items()) report[key] = value;
  } else {
    report["volume_mm3"] = result.labelmap.count() * image.geometry.spacing.prod();
  }
  report["control_vertices"] = result.mesh.vertexCount();
  report["levels"] = result.levels.back().level;
  report["iterations"] = result.steps;
  report["final_energy"] = result.levels.back().energy;
  report["seconds"] = run.seconds;
  report["stage_seconds"] = {{"crop", result.seconds.crop},
                             {"edge_potential", result.seconds.potential},
                             {"evolution", result.seconds.evolution},
                             {"voxelize", result.seconds.voxelize}};
  if (in.segment.sliceEnds.enabled) {
    const SliceEnds& ends = result.sliceEnds;
    nlohmann::ordered_json marched = nlohmann::ordered_json::array(), springs = nlohmann::ordered_json::array();
    for (const SliceEnd& end : ends.ends)
      marched.push_back({{"from_lps_mm", {end.start.x(), end.start.y(), end.start.z()}},
                         {"to_lps_mm", {end.end.x(), end.end.y(), end.end.z()}},
                         {"length_mm", end.length},
                         {"stopped_by_reach", end.stoppedByReach}});
    for (const Landmark& spring : ends.springs)
      springs.push_back({spring.position.x(), spring.position.y(), spring.position.z()});
    report["slice_ends"] = {{"axis", ends.axis},
                            {"slices", ends.slices},
                            {"median", ends.median},
                            {"spread", ends.spread},
                            {"ends", marched},
                            {"springs", ends.springs.size()},
                            {"spring_points_lps_mm", springs}};
  }
  report["region_of_interest"] = {{"first_voxel", result.regionFirst}, {"size_voxels", result.regionSize}};
  report["initial_volume_mm3"] = result.initialVolume;
  report["surface_volume_mm3"] = result.volume;
  report["surface_outside_region"] = result.outsideRegion;
  if (std::isfinite(result.surfaceOnEdges)) report["surface_on_edges"] = result.surfaceOnEdges;
  run.warnings = result.warnings;
  if (run.seed) {
    const std::vector<std::string> seed = seedWarnings(*run.seed);
    run.warnings.insert(run.warnings.begin(), seed.begin(), seed.end());
  }
  report["warnings"] = run.warnings;
  nlohmann::ordered_json residuals = nlohmann::ordered_json::array();
  for (std::size_t i = 0; i < springs.size(); ++i) {
    residuals.push_back({{"label", springs[i].label},
                         {"position_lps_mm", {springs[i].position.x(), springs[i].position.y(),
                                              springs[i].position.z()}},
                         {"distance_mm", result.landmarkDistances[i]}});
    if (i < result.landmarkEdgeDistances.size() && std::isfinite(result.landmarkEdgeDistances[i]))
      residuals.back()["edge_distance_mm"] = result.landmarkEdgeDistances[i];
  }
  report["landmark_residuals"] = residuals;
  nlohmann::ordered_json levels = nlohmann::ordered_json::array();
  for (const auto& level : result.levels) levels.push_back(levelJson(level, -1, -1));  // no fit error in segmentation
  report["per_level"] = levels;
  nlohmann::ordered_json parameters = simulationJson(in.segment.simulation);
  parameters["potential"] = in.potential;
  parameters["sigma_mm"] = in.segment.edges.sigma;
  if (in.segment.edges.method == EdgeMethod::MongaDeriche) {
    const EdgeScale& scale = result.edgeScale;
    parameters["edge_reference"] = referenceName(scale.reference);
    parameters["edge_reference_magnitude"] = scale.magnitude;
    parameters["edge_low"] = scale.fractions.low;
    parameters["edge_high"] = scale.fractions.high;
  }
  parameters["capture_range_mm"] = in.segment.edges.captureRange;
  parameters["image_force"] = in.segment.imageForce;
  parameters["landmark_stiffness"] = in.segment.landmarkStiffness;
  parameters["landmark_dead_zone_mm"] = in.segment.landmarkDeadZone;
  parameters["landmark_tolerance_mm"] = in.segment.landmarkTolerance;
  parameters["inflation"] = in.segment.inflation;
  parameters["margin_mm"] = in.segment.margin;
  report["parameters"] = parameters;
  return run;
}

}  // namespace dynsub::app
