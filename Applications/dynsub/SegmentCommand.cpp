// dynsub segment: a structure in a 3D image from image forces and expert landmarks (Segmentation.h).
#include <cmath>
#include <filesystem>
#include <future>
#include <iomanip>
#include <iostream>
#include <memory>
#include <sstream>

#include <CLI/CLI.hpp>

#include "CommandLine.h"
#include "Commands.h"
#include "FigureOutputs.h"
#include "SegmentRun.h"
#include "dynsub/Error.h"
#include "dynsub/FileNames.h"
#include "dynsub/ImageIO.h"
#include "dynsub/Metrics.h"
#include "dynsub/ModelOutputs.h"
#include "dynsub/ParallelFor.h"
#include "dynsub/SeedGrowth.h"
#include "dynsub/Segmentation.h"
#include "dynsub/SurfaceWriter.h"

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

// The options as SegmentOptions; throws dynsub::Error on impossible ones.
SegmentOptions segmentOptions(const SegmentCommandOptions& o) {
  SegmentOptions segment = o.segment;
  if (o.potential == "gradient") segment.edges.method = EdgeMethod::GradientMagnitude;
  segment.simulation = o.simulation.apply(segment.simulation);
  // --edge-low / --edge-high are fractions of the reference that will be used:
  // the landmarks' whenever there are landmarks and it is not --edge-reference
  // image (landmarks off every edge are an error, not a silent switch).
  EdgeOptions& edges = segment.edges;
  edges.reference = o.edgeReference == "image" ? EdgeReference::Image : EdgeReference::Landmarks;
  const bool pointsOnBoundary = !o.landmarks.empty() || o.init.rfind("seed:", 0) == 0;  // see chooseStart
  Hysteresis& thresholds =
      edges.reference == EdgeReference::Landmarks && pointsOnBoundary ? edges.ofLandmarks : edges.ofImage;
  if (o.edgeLowOption->count()) thresholds.low = o.edgeLow;
  if (o.edgeHighOption->count()) thresholds.high = o.edgeHigh;
  checkSegmentOptions(segment);
  if (!o.reference.empty() && o.referenceLabels.empty())
    throw Error("--reference needs --reference-label N[,M...]: the label value(s) of the structure");
  return segment;
}

// The expert's labelmap of the structure, on the image's grid.
Mask readReference(const SegmentCommandOptions& o, const Volume& image) {
  const Volume labels = readVolume(o.reference);
  if (!labels.geometry.sameGridAs(image.geometry))
    throw Error(o.reference, "the reference is not on the image's grid (size, origin, spacing or direction differ)");
  Mask reference = selectLabels(labels, o.referenceLabels);
  if (reference.count() == 0) throw Error(o.reference, "no voxel has the reference label(s)");
  return reference;
}

// surface.vtp, control_mesh.obj, report.json, labelmap.nii.gz, convergence.csv and the figures, all or none.
void writeSegmentOutputs(const std::filesystem::path& dir, const SegmentRun& run, const Volume& image,
                         const FigureOptions& figures) {
  const SegmentResult& result = run.result;
  writeModelOutputs(
      dir, result.mesh, result.surface, run.report,
      [&](OutputSet& outputs) {
        const std::string labelmapPath = outputs.add("labelmap.nii.gz");
        const auto labelmap = [&] { writeMask(run.labelmap, labelmapPath); };
        const auto figuresAndRecord = [&] {
          addFigureOutputs(outputs, figures, result.mesh, result.surface, run.history, &image,
                           landmarkPositions(run.springs), Matrix3X(), result.surfaceEdgeDistances);
        };
        // NB: with figures, the labelmap is compressed on a thread of its own
        // while they render on this one (a tenth of them). Without, this
        // thread has only convergence.csv to write, and writes the labelmap
        // too: a thread of its own took fresh 4 kB pages for the labelmap's
        // 7 MB where this one reuses the main heap's. The labelmap's error,
        // if any, comes first either way.
        if (figures.figures) {
          alongside(labelmap, figuresAndRecord);
        } else {
          labelmap();
          figuresAndRecord();
        }
      },
      result.surfaceEdgeDistances.size()
          ? std::vector<PointScalars>{{kEdgeDistanceScalars, result.surfaceEdgeDistances}}
          : std::vector<PointScalars>{},
      "LPS");
}

void printSummary(const SegmentCommandOptions& o, const SegmentRun& run, const Volume& image) {
  const SegmentResult& result = run.result;
  std::cout << std::fixed << std::setprecision(1) << "segmented " << run.labelmap.count() * image.geometry.spacing.prod()
            << " mm^3 with " << result.mesh.vertexCount() << " control vertices (" << result.levels.back().level
            << " refinement(s), " << result.steps << " steps) in " << run.seconds << " s\n";
  const std::string carried = carriedPastSlices(run.result);
  if (!carried.empty())
    std::cout << "followed the structure's tissue past the outermost clicked slices and pulled the surface there: "
              << carried << " (--slice-ends false if your clicks already reach its ends)\n";
  for (const std::string& warning : run.warnings) std::cerr << "warning: " << warning << '\n';
  if (!o.reference.empty())
    std::cout << std::setprecision(3) << "Dice " << run.metrics.dice << ", mean surface distance "
              << run.metrics.meanSurfaceDistance << " mm, HD95 " << run.metrics.hd95 << " mm against " << o.reference
              << '\n';
  std::cout << "wrote " << (std::filesystem::path(o.out) / "surface.vtp").string()
            << ", control_mesh.obj, labelmap.nii.gz, report.json, convergence.csv"
            << (o.figures.figures ? " and the figures that could be rendered" : "") << '\n';
}

void runSegment(const SegmentCommandOptions& o) {
  // Every input is read and checked before anything is written.
  SegmentInputs inputs;
  inputs.segment = segmentOptions(o);
  const Volume image = readVolume(o.image);
  if (!o.landmarks.empty()) inputs.landmarks = readLandmarks(o.landmarks);
  // NB: the reference is needed only to score the result, and reading it
  // (a whole labelmap, inflated and converted) took a fifth of the caudate
  // demo's command: it is read on a second thread while the segmentation
  // runs, and its errors (a missing file at once) still come before any
  // output is written.
  std::shared_future<Mask> reference;
  if (!o.reference.empty()) {
    requireExisting(o.reference);  // before the segmentation; its other errors come with its reading
    reference = std::async(std::launch::async, [&o, &image] { return readReference(o, image); }).share();
    inputs.reference = [reference]() -> const Mask& { return reference.get(); };
    inputs.referencePath = o.reference;
    inputs.referenceLabels = o.referenceLabels;
  }
  inputs.image = o.image;
  inputs.landmarkSource = o.landmarks;
  inputs.init = parseInitialModel(o.init, "--init");
  if (inputs.init.kind == InitialModel::Kind::FromLandmarks && inputs.landmarks.size() < 4)
    throw Error("--init auto builds the initial model from the landmarks: give at least 4 with --landmarks, "
                "or use --init seed:x,y,z, --init sphere:x,y,z,r or --init MESH");
  inputs.seed = o.seed;
  inputs.potential = o.potential;
  const std::filesystem::path dir(o.out);
  prepareOutputDirectory(dir);
  o.figures.prepare();

  ProgressLine line;
  const SegmentRun run = runSegmentation(image, inputs, line.callback());
  line.finish();
  writeSegmentOutputs(dir, run, image, o.figures);
  printSummary(o, run, image);
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
  command->add_option("--landmark-dead-zone", o->segment.landmarkDeadZone,
                      "A landmark's spring pulls only where the surface is farther than this from the click, mm "
                      "(a click's error; 0: a plain spring)")
      ->default_val(o->segment.landmarkDeadZone)
      ->check(CLI::NonNegativeNumber);
  command->add_option("--landmark-tolerance", o->segment.landmarkTolerance,
                      "Refine at equilibrium while a landmark is farther than this from the surface, mm")
      ->default_val(o->segment.landmarkTolerance);
  command->add_option("--inflation", o->segment.inflation, "Pressure along the normal, N/mm^2 (> 0 grows)")
      ->default_val(o->segment.inflation);
  command->add_option("--margin", o->segment.margin, "Region of interest around the model and landmarks, mm")
      ->default_val(o->segment.margin);
  command->add_option("--slice-ends", o->segment.sliceEnds.enabled,
                      "For landmarks on slices: follow the tissue between the clicked slices beyond them and add "
                      "soft springs where it ends, so that the structure's unclicked ends are reached (true/false; "
                      "false when your clicks reach both ends: the march can then go on into like tissue)")
      ->default_val(o->segment.sliceEnds.enabled);
  command->add_option("--end-pressure", o->segment.sliceEnds.pressure,
                      "With --slice-ends: the pressure beyond the outermost clicked slices, N/mm^2 at full "
                      "strength, that grows the surface through tissue like that just inside the clicks and "
                      "pushes it back from tissue like that just outside them (0: none)")
      ->default_val(o->segment.sliceEnds.pressure)
      ->check(CLI::NonNegativeNumber);
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
