// dynsub segment: a structure in a 3D image from image forces and expert landmarks (Segmentation.h).
#include <cmath>
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <memory>
#include <sstream>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "Commands.h"
#include "FigureOutputs.h"
#include "Reporting.h"
#include "dynsub/ClosestPoint.h"
#include "dynsub/Error.h"
#include "dynsub/ImageIO.h"
#include "dynsub/MeshIO.h"
#include "dynsub/Metrics.h"
#include "dynsub/SeedGrowth.h"
#include "dynsub/Segmentation.h"

namespace dynsub::app {

namespace {

struct SegmentCommandOptions {
  std::string image;
  std::string out;
  std::string landmarks;
  std::string init = "auto";
  std::string reference;
  std::vector<int> referenceLabels;
  std::string potential = "edges";
  std::string edgeReference = "landmarks";
  double edgeLow = 0, edgeHigh = 0;  // used only when given (CLI::Option::count)
  const CLI::Option* edgeLowOption = nullptr;
  const CLI::Option* edgeHighOption = nullptr;
  SegmentOptions segment;
  SeedOptions seed;
  SimulationArguments simulation;
  FigureOptions figures;
};

// Where the evolution starts, and which points its springs pull to.
struct Start {
  ControlMesh initial;
  std::vector<Landmark> springs;  // the user's landmarks, or the seed region's boundary without them
  std::unique_ptr<SeedRegion> seed;  // for --init seed:
};

// "x,y,z[,r]" after a prefix: `count` finite numbers.
std::vector<double> numbersAfter(const std::string& value, std::size_t prefix, int count, const char* expected) {
  std::stringstream in(value.substr(prefix));
  std::vector<double> v(count);
  char comma = ',';
  for (int i = 0; i < count; ++i)
    if (!(in >> v[i]) || !std::isfinite(v[i]) || (i + 1 < count && (!(in >> comma) || comma != ',')))
      throw Error("--init " + value + ": expected " + expected + " (LPS mm)");
  if (in >> comma) throw Error("--init " + value + ": expected " + expected + " (LPS mm)");
  return v;
}

Start chooseStart(SegmentCommandOptions& o, const Volume& image, const std::vector<Landmark>& landmarks) {
  Start start;
  start.springs = landmarks;
  if (o.init == "auto") {
    if (landmarks.size() < 4)
      throw Error("--init auto builds the initial model from the landmarks: give at least 4 with --landmarks, "
                  "or use --init seed:x,y,z, --init sphere:x,y,z,r or --init MESH");
    start.initial = initialFromLandmarks(landmarks);
  } else if (o.init.rfind("sphere:", 0) == 0) {
    const std::vector<double> v = numbersAfter(o.init, 7, 4, "sphere:x,y,z,r");
    start.initial = initialSphere(Vector3(v[0], v[1], v[2]), v[3]);
  } else if (o.init.rfind("seed:", 0) == 0) {
    // The region the click's tissue fills (SeedGrowth.h) gives the initial
    // model; without landmarks its boundary points are the springs, softer
    // than an expert's clicks.
    const std::vector<double> v = numbersAfter(o.init, 5, 3, "seed:x,y,z");
    start.seed = std::make_unique<SeedRegion>(growFromSeed(image, Vector3(v[0], v[1], v[2]), o.seed));
    start.initial = initialFromLandmarks(start.seed->boundary);
    if (landmarks.empty()) {
      start.springs = start.seed->boundary;
      o.segment.landmarkStiffness = o.seed.stiffness;
    }
  } else {
    start.initial = readControlMesh(o.init);
    if (!start.initial.isClosed()) throw Error(o.init, "the initial model must be a closed control mesh");
  }
  return start;
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

void runSegment(SegmentCommandOptions o) {
  if (o.potential == "gradient") o.segment.edges.method = EdgeMethod::GradientMagnitude;
  o.segment.simulation = o.simulation.apply(o.segment.simulation);
  // --edge-low / --edge-high are fractions of the reference that will be used:
  // the landmarks' whenever there are landmarks and it is not --edge-reference
  // image (landmarks off every edge are an error, not a silent switch).
  EdgeOptions& edges = o.segment.edges;
  edges.reference = o.edgeReference == "image" ? EdgeReference::Image : EdgeReference::Landmarks;
  const bool pointsOnBoundary = !o.landmarks.empty() || o.init.rfind("seed:", 0) == 0;  // see chooseStart
  Hysteresis& thresholds =
      edges.reference == EdgeReference::Landmarks && pointsOnBoundary ? edges.ofLandmarks : edges.ofImage;
  if (o.edgeLowOption->count()) thresholds.low = o.edgeLow;
  if (o.edgeHighOption->count()) thresholds.high = o.edgeHigh;
  checkSegmentOptions(o.segment);
  if (!o.reference.empty() && o.referenceLabels.empty())
    throw Error("--reference needs --reference-label N[,M...]: the label value(s) of the structure");

  // Every input is read and checked before anything is written.
  const Volume image = readVolume(o.image);
  const std::vector<Landmark> landmarks = o.landmarks.empty() ? std::vector<Landmark>{} : readLandmarks(o.landmarks);
  Mask reference;
  if (!o.reference.empty()) {
    const Volume labels = readVolume(o.reference);
    if (!labels.geometry.sameGridAs(image.geometry))
      throw Error(o.reference, "the reference is not on the image's grid (size, origin, spacing or direction differ)");
    reference = selectLabels(labels, o.referenceLabels);
    if (reference.count() == 0) throw Error(o.reference, "no voxel has the reference label(s)");
  }
  const Start start = chooseStart(o, image, landmarks);
  const ControlMesh& initial = start.initial;
  const std::vector<Landmark>& springs = start.springs;
  const std::filesystem::path dir(o.out);
  prepareOutputDirectory(dir);

  const auto started = std::chrono::steady_clock::now();
  ProgressLine line;
  // The rms landmark distance every 5 steps, the landmarks' nearest points
  // tracked from sample to sample (a new locator only when the level changes).
  const Matrix3X landmarkPoints = landmarkPositions(springs);
  TrackedDistances tracked(landmarkPoints);
  ConvergenceRecorder recorder(
      "rms landmark distance (mm)",
      springs.empty() ? ConvergenceRecorder::FitError()
                        : [&](const Progress& p) {
                            const Eigen::VectorXd d = tracked.measure(*p.surface, p.level, *p.controlPoints);
                            return std::sqrt(d.squaredNorm() / static_cast<double>(d.size()));
                          },
      5);
  const SegmentResult result = [&] {
    try {
      return segment(image, springs, initial, o.segment, recorder.callback(line.callback()));
    } catch (const LandmarksOffEdges& error) {
      // Name the file the points came from, and the options that help.
      throw Error(o.landmarks, std::string(error.what()) + " (--edge-landmark-reach, --edge-reference image)");
    } catch (const LandmarkError& error) {
      throw Error(o.landmarks, error.what());
    }
  }();
  line.finish();
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();

  nlohmann::ordered_json report;
  report["image"] = o.image;
  report["landmarks"] = o.landmarks;
  report["landmark_count"] = landmarks.size();
  report["init"] = o.init;
  if (const SeedRegion* seed = start.seed.get()) {
    report["seed"] = {{"position_lps_mm", {seed->click.x(), seed->click.y(), seed->click.z()}},
                      {"median", seed->median},
                      {"spread", seed->spread},
                      {"intensity_window", {seed->low, seed->high}},
                      {"window_spreads", seed->window},
                      {"opening_mm", seed->opening},
                      {"region_volume_mm3", seed->mask.count() * seed->mask.geometry.spacing.prod()},
                      {"boundary_points", seed->boundary.size()},
                      {"springs", landmarks.empty() ? "boundary points" : "landmarks"},
                      {"leaked", seed->touchesReach}};
  }
  OverlapMetrics metrics;
  if (!o.reference.empty()) {
    metrics = compareMasks(result.labelmap, reference);
    report["reference"] = o.reference;
    report["reference_labels"] = o.referenceLabels;
    const nlohmann::ordered_json measured = metricsJson(metrics);
    for (const auto& [key, value] : measured.items()) report[key] = value;
  } else {
    report["volume_mm3"] = result.labelmap.count() * image.geometry.spacing.prod();
  }
  report["control_vertices"] = result.mesh.vertexCount();
  report["levels"] = result.levels.back().level;
  report["iterations"] = result.steps;
  report["final_energy"] = result.levels.back().energy;
  report["seconds"] = seconds;
  report["stage_seconds"] = {{"crop", result.seconds.crop},
                             {"edge_potential", result.seconds.potential},
                             {"evolution", result.seconds.evolution},
                             {"voxelize", result.seconds.voxelize}};
  report["region_of_interest"] = {{"first_voxel", result.regionFirst}, {"size_voxels", result.regionSize}};
  report["initial_volume_mm3"] = result.initialVolume;
  report["surface_volume_mm3"] = result.volume;
  report["surface_outside_region"] = result.outsideRegion;
  if (std::isfinite(result.surfaceOnEdges)) report["surface_on_edges"] = result.surfaceOnEdges;
  std::vector<std::string> warnings = result.warnings;
  if (start.seed) {
    const std::vector<std::string> seed = seedWarnings(*start.seed);
    warnings.insert(warnings.begin(), seed.begin(), seed.end());
  }
  report["warnings"] = warnings;
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
  nlohmann::ordered_json parameters = simulationJson(o.segment.simulation);
  parameters["potential"] = o.potential;
  parameters["sigma_mm"] = o.segment.edges.sigma;
  if (o.segment.edges.method == EdgeMethod::MongaDeriche) {
    const EdgeScale& scale = result.edgeScale;
    parameters["edge_reference"] = referenceName(scale.reference);
    parameters["edge_reference_magnitude"] = scale.magnitude;
    parameters["edge_low"] = scale.fractions.low;
    parameters["edge_high"] = scale.fractions.high;
  }
  parameters["capture_range_mm"] = o.segment.edges.captureRange;
  parameters["image_force"] = o.segment.imageForce;
  parameters["landmark_stiffness"] = o.segment.landmarkStiffness;
  parameters["landmark_tolerance_mm"] = o.segment.landmarkTolerance;
  parameters["inflation"] = o.segment.inflation;
  parameters["margin_mm"] = o.segment.margin;
  report["parameters"] = parameters;

  writeModelOutputs(dir, result.mesh, report, [&](OutputSet& outputs) {
    writeMask(result.labelmap, outputs.add("labelmap.nii.gz"));
    addFigureOutputs(outputs, o.figures, result.mesh, recorder.history(), &image, landmarkPoints, Matrix3X());
  }, result.surfaceEdgeDistances.size() ? std::vector<PointScalars>{{"edge_distance_mm", result.surfaceEdgeDistances}}
                                        : std::vector<PointScalars>{});

  std::cout << std::fixed << std::setprecision(1) << "segmented " << result.labelmap.count() * image.geometry.spacing.prod()
            << " mm^3 with " << result.mesh.vertexCount() << " control vertices (" << result.levels.back().level
            << " refinement(s), " << result.steps << " steps) in " << seconds << " s\n";
  for (const std::string& warning : warnings) std::cerr << "warning: " << warning << '\n';
  if (!o.reference.empty())
    std::cout << std::setprecision(3) << "Dice " << metrics.dice << ", mean surface distance "
              << metrics.meanSurfaceDistance << " mm, HD95 " << metrics.hd95 << " mm against " << o.reference
              << '\n';
  std::cout << "wrote " << (dir / "surface.vtp").string()
            << ", control_mesh.obj, labelmap.nii.gz, report.json, convergence.csv"
            << (o.figures.figures ? " and the figures that could be rendered" : "") << '\n';
}

}  // namespace

void addSegmentCommand(CLI::App& app) {
  auto o = std::make_shared<SegmentCommandOptions>();
  CLI::App* command = app.add_subcommand(
      "segment",
      "Segment a structure in a 3D image with a dynamic subdivision surface pulled by image edges and by "
      "springs to landmarks an expert placed on its boundary; the surface is refined at equilibrium.\n"
      "Writes DIR/surface.vtp (LPS mm), DIR/control_mesh.obj, DIR/labelmap.nii.gz (on the image's grid) and "
      "DIR/report.json, DIR/convergence.csv, and the figures DIR/slices.png, DIR/surface3d.png and "
      "DIR/convergence.png.");
  command->add_option("IMAGE", o->image, "3D image: .nii/.nii.gz, .nrrd, .mha/.mhd, or a DICOM series directory")
      ->required();
  command->add_option("--out", o->out, "Output directory (created if missing; its parent must exist)")->required();
  command->add_option("--landmarks", o->landmarks, "Boundary points: .mrk.json, .fcsv or .csv (x,y,z in LPS mm)");
  command->add_option("--init", o->init,
                      "Initial model: auto (the 98-vertex cube inside the landmarks' PCA ellipsoid), "
                      "seed:x,y,z (one click inside the structure, LPS mm: grown through the tissue like the "
                      "click's, its boundary the springs when no --landmarks are given), "
                      "sphere:x,y,z,r (LPS mm), or a closed control mesh file in LPS mm")
      ->default_val("auto");
  command->add_option("--reference", o->reference, "Reference labelmap on the image's grid, for Dice and distances");
  command->add_option("--reference-label", o->referenceLabels, "Label value(s) of the structure in --reference")
      ->delimiter(',');
  command->add_option("--potential", o->potential, "edges (Monga-Deriche edge distance) or gradient (|grad I|)")
      ->check(CLI::IsMember({"edges", "gradient"}))
      ->default_val("edges");
  command->add_option("--sigma", o->segment.edges.sigma, "Gaussian smoothing of the edge detector, mm")
      ->default_val(o->segment.edges.sigma);
  const EdgeOptions edgeDefaults;
  command->add_option("--edge-reference", o->edgeReference,
                      "What the edge thresholds are fractions of: landmarks (the median over the landmarks "
                      "of the strongest gradient within --edge-landmark-reach of each, the boundary the expert "
                      "marked; the image's without landmarks; an error if the landmarks are on no edge) or image "
                      "(the 99th-percentile gradient)")
      ->check(CLI::IsMember({"landmarks", "image"}))
      ->default_val("landmarks");
  std::ostringstream lowHelp, highHelp;
  lowHelp << "Hysteresis low threshold, a fraction of the edge reference (default " << edgeDefaults.ofLandmarks.low
          << " of the landmarks', " << edgeDefaults.ofImage.low << " of the image's)";
  highHelp << "Hysteresis high threshold, the same unit (default " << edgeDefaults.ofLandmarks.high
           << " of the landmarks', " << edgeDefaults.ofImage.high << " of the image's)";
  command->add_option("--edge-landmark-reach", o->segment.edges.landmarkReach,
                      "With --edge-reference landmarks, a landmark's edge is the strongest gradient this close, mm")
      ->default_val(o->segment.edges.landmarkReach);
  o->edgeLowOption = command->add_option("--edge-low", o->edgeLow, lowHelp.str());
  o->edgeHighOption = command->add_option("--edge-high", o->edgeHigh, highHelp.str());
  command->add_option("--capture-range", o->segment.edges.captureRange, "Distance from edges with a force, mm")
      ->default_val(o->segment.edges.captureRange);
  command->add_option("--image-force", o->segment.imageForce, "Image force k, N/mm^2 of surface")
      ->default_val(o->segment.imageForce);
  command->add_option("--landmark-stiffness", o->segment.landmarkStiffness, "Spring stiffness per landmark, N/mm")
      ->default_val(o->segment.landmarkStiffness);
  command->add_option("--landmark-tolerance", o->segment.landmarkTolerance,
                      "Refine at equilibrium while a landmark is farther than this from the surface, mm")
      ->default_val(o->segment.landmarkTolerance);
  command->add_option("--inflation", o->segment.inflation, "Pressure along the normal, N/mm^2 (> 0 grows)")
      ->default_val(o->segment.inflation);
  command->add_option("--margin", o->segment.margin, "Region of interest around the model and landmarks, mm")
      ->default_val(o->segment.margin);
  command->add_option("--seed-window", o->seed.window,
                      "With --init seed: the intensity window grown through, in robust spreads (1.4826 MAD) of "
                      "the intensities near the click either side of their median")
      ->default_val(o->seed.window)
      ->check(CLI::PositiveNumber);
  command->add_option("--seed-opening", o->seed.opening,
                      "With --init seed: the radius (mm) of the opening that cuts thin bridges to like tissue")
      ->default_val(o->seed.opening)
      ->check(CLI::NonNegativeNumber);
  command->add_option("--seed-reach", o->seed.reach, "With --init seed: how far (mm) the region may grow from the click")
      ->default_val(o->seed.reach)
      ->check(CLI::PositiveNumber);
  o->simulation.addOptions(*command, SegmentOptions::defaultSimulation());
  o->figures.addOptions(*command);
  command->callback([o] { runSegment(*o); });
}

}  // namespace dynsub::app
