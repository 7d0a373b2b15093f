#include "SegmentRun.h"

#include <chrono>
#include <cmath>
#include <iomanip>
#include <sstream>

#include "dynsub/ClosestPoint.h"
#include "dynsub/Error.h"
#include "dynsub/Labelmap.h"
#include "dynsub/MeshIO.h"
#include "dynsub/ModelOutputs.h"

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
      try {
        return initialFromLandmarks(in.landmarks);
      } catch (const LandmarkError& error) {
        throw Error(in.landmarkSource, error.what());
      }
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
  const auto voxelizing = std::chrono::steady_clock::now();
  run.labelmap = labelmapOf(run.result.surface, image.geometry);
  const double voxelizeSeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - voxelizing).count();
  run.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  run.history = recorder.history();
  const SegmentResult& result = run.result;

  Report& report = run.report;
  report.set("image", in.image);
  report.set("landmarks", in.landmarkSource);
  report.set("landmark_count", in.landmarks.size());
  report.set("init", in.init.text);
  if (const SeedRegion* seed = run.seed.get()) {
    Report r;
    r.set("position_lps_mm", seed->click);
    r.set("median", seed->median);
    r.set("spread", seed->spread);
    r.set("intensity_window", std::vector<double>{seed->low, seed->high});
    r.set("window_spreads", seed->window);
    r.set("opening_mm", seed->opening);
    r.set("region_volume_mm3", regionVolume(*seed));
    r.set("narrower_window_volume_mm3", seed->narrowerWindowVolume);
    r.set("boundary_points", seed->boundary.size());
    r.set("springs", in.landmarks.empty() ? "boundary points" : "landmarks");
    r.set("leaked", probablyLeaked(*seed));
    report.set("seed", r);
  }
  if (in.reference) {
    run.metrics = compareMasks(run.labelmap, in.reference());
    report.set("reference", in.referencePath);
    report.set("reference_labels", in.referenceLabels);
    report.merge(metricsReport(run.metrics));
  } else {
    report.set("volume_mm3", run.labelmap.count() * image.geometry.spacing.prod());
  }
  report.set("control_vertices", result.mesh.vertexCount());
  report.set("levels", result.levels.back().level);
  report.set("iterations", result.steps);
  report.set("final_energy", result.levels.back().energy);
  report.set("seconds", run.seconds);
  Report stages;
  stages.set("crop", result.seconds.crop);
  stages.set("edge_potential", result.seconds.potential);
  stages.set("evolution", result.seconds.evolution);
  stages.set("voxelize", voxelizeSeconds);
  report.set("stage_seconds", stages);
  if (in.segment.sliceEnds.enabled) {
    const SliceEnds& ends = result.sliceEnds;
    std::vector<Report> marched;
    for (const SliceEnd& end : ends.ends) {
      Report r;
      r.set("from_lps_mm", end.start);
      r.set("to_lps_mm", end.end);
      r.set("length_mm", end.length);
      r.set("stopped_by_reach", end.stoppedByReach);
      r.set("pressure", end.pressed);
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
    report.set("slice_ends", r);
  }
  Report region;
  region.set("first_voxel", result.regionFirst);
  region.set("size_voxels", result.regionSize);
  report.set("region_of_interest", region);
  report.set("initial_volume_mm3", result.initialVolume);
  report.set("surface_volume_mm3", result.volume);
  report.set("surface_outside_region", result.outsideRegion);
  if (std::isfinite(result.surfaceOnEdges)) report.set("surface_on_edges", result.surfaceOnEdges);
  run.warnings = result.warnings;
  if (run.seed) {
    const std::vector<std::string> seed = seedWarnings(*run.seed);
    run.warnings.insert(run.warnings.begin(), seed.begin(), seed.end());
  }
  report.set("warnings", run.warnings);
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
  Report parameters = simulationReport(in.segment.simulation);
  parameters.set("potential", in.potential);
  parameters.set("sigma_mm", in.segment.edges.sigma);
  if (in.segment.edges.method == EdgeMethod::MongaDeriche) {
    const EdgeScale& scale = result.edgeScale;
    parameters.set("edge_reference", referenceName(scale.reference));
    parameters.set("edge_reference_magnitude", scale.magnitude);
    parameters.set("edge_low", scale.fractions.low);
    parameters.set("edge_high", scale.fractions.high);
  }
  parameters.set("capture_range_mm", in.segment.edges.captureRange);
  parameters.set("image_force", in.segment.imageForce);
  parameters.set("landmark_stiffness", in.segment.landmarkStiffness);
  parameters.set("landmark_dead_zone_mm", in.segment.landmarkDeadZone);
  parameters.set("landmark_tolerance_mm", in.segment.landmarkTolerance);
  parameters.set("inflation", in.segment.inflation);
  parameters.set("margin_mm", in.segment.margin);
  parameters.set("slice_ends", in.segment.sliceEnds.enabled);
  parameters.set("end_pressure", in.segment.sliceEnds.pressure);
  report.set("parameters", parameters);
  return run;
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

}  // namespace dynsub::app
