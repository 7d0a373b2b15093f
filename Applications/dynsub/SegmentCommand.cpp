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
#include "dynsub/Error.h"
#include "dynsub/FileNames.h"
#include "dynsub/ImageIO.h"
#include "dynsub/Metrics.h"
#include "dynsub/ModelOutputs.h"
#include "dynsub/ParallelFor.h"
#include "dynsub/SegmentImage.h"
#include "dynsub/SurfaceWriter.h"

namespace dynsub::app {

namespace {

// What `dynsub segment` reads besides the parameters, and the parameters.
struct Arguments {
  std::string image;
  std::string out;
  std::string landmarks;
  std::string init = "auto";
  std::string reference;
  std::vector<int> referenceLabels;
  std::string atlas = kDefaultAtlasImage;
  std::string atlasLabels = kDefaultAtlasLabels;
  std::string atlasLabel;
  std::string inside;
  SegmentParameters parameters;
  FigureOptions figures;
};

// The expert's labelmap of the structure, on the image's grid.
Mask readReference(const Arguments& o, const Volume& image) {
  const Volume labels = readVolume(o.reference);
  if (!labels.geometry.sameGridAs(image.geometry))
    throw Error(o.reference, "the reference is not on the image's grid (size, origin, spacing or direction differ)");
  Mask reference = selectLabels(labels, o.referenceLabels);
  if (reference.count() == 0) throw Error(o.reference, "no voxel has the reference label(s)");
  return reference;
}

// surface.vtp, control_mesh.obj, report.json, labelmap.nii.gz, convergence.csv and the figures, all or none.
void writeSegmentOutputs(const std::filesystem::path& dir, const SegmentOutcome& outcome, const Volume& image,
                         const FigureOptions& figures) {
  const SegmentResult& result = outcome.result;
  writeModelOutputs(
      dir, result.mesh, result.surface, outcome.report,
      [&](OutputSet& outputs) {
        const std::string labelmapPath = outputs.add("labelmap.nii.gz");
        const auto labelmap = [&] { writeMask(outcome.labelmap, labelmapPath); };
        const auto figuresAndRecord = [&] {
          addFigureOutputs(outputs, figures, result.mesh, result.surface, outcome.history, &image,
                           landmarkPositions(outcome.springs), MatrixX3(), result.surfaceEdgeDistances);
        };
        // With figures, the labelmap is compressed on a thread of its own
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

void printSummary(const Arguments& o, const SegmentOutcome& outcome, const Volume& image) {
  const SegmentResult& result = outcome.result;
  std::cout << std::fixed << std::setprecision(1) << "segmented " << outcome.labelmap.count() * image.geometry.spacing.prod()
            << " mm^3 with " << result.mesh.vertexCount() << " control vertices (" << result.levels.back().level
            << " refinement(s), " << result.steps << " steps) in " << outcome.seconds << " s\n";
  const std::string carried = carriedPastSlices(outcome.result);
  if (!carried.empty())
    std::cout << "followed the structure's tissue past the outermost clicked slices and pulled the surface there: "
              << carried << " (--slice-ends false if your clicks already reach its ends)\n";
  for (const std::string& warning : outcome.warnings) std::cerr << "warning: " << warning << '\n';
  for (const TrustFlag& flag : outcome.trustFlags)
    std::cerr << "not to trust (" << flag.name << "): " << flag.message << '\n';
  if (!o.reference.empty())
    std::cout << std::setprecision(3) << "Dice " << outcome.metrics.dice << ", mean surface distance "
              << outcome.metrics.meanSurfaceDistance << " mm, HD95 " << outcome.metrics.hd95 << " mm against " << o.reference
              << '\n';
  std::cout << "wrote " << (std::filesystem::path(o.out) / "surface.vtp").string()
            << ", control_mesh.obj, labelmap.nii.gz, report.json, convergence.csv"
            << (o.figures.figures ? " and the figures that could be rendered" : "") << '\n';
}

void runSegment(const Arguments& o) {
  // Every input is read and checked before anything is written.
  if (!o.reference.empty() && o.referenceLabels.empty())
    throw Error("--reference needs --reference-label N[,M...]: the label value(s) of the structure");
  SegmentInputs inputs;
  inputs.start = parseSegmentStart(o.init, "--init");
  const Volume image = readVolume(o.image);
  if (!o.landmarks.empty()) inputs.landmarks = readLandmarks(o.landmarks, &inputs.landmarkSystem);
  inputs.image = o.image;
  inputs.landmarkSource = o.landmarks;
  if (!o.inside.empty()) inputs.inside = parsePoint(o.inside, "--inside");
  if (inputs.start.kind == SegmentStart::Kind::Atlas) {
    if (o.atlasLabel.empty())
      throw Error("--init atlas needs --atlas-label N[,M...] or a name from the atlas's table (e.g. Caudate_L)");
    inputs.atlas = std::make_shared<const Atlas>(readAtlas(o.atlas, o.atlasLabels));
    inputs.atlasLabels = atlasLabelValues(*inputs.atlas, o.atlasLabel);
  } else if (!o.atlasLabel.empty()) {
    throw Error("--atlas-label serves an atlas start: add --init atlas");
  }
  checkSegmentInputs(inputs, o.parameters);
  // The reference is needed only to score the result, and reading it
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
  const std::filesystem::path dir(o.out);
  prepareOutputDirectory(dir);
  o.figures.prepare();

  ProgressLine line;
  const SegmentOutcome outcome = segmentImage(image, inputs, o.parameters, line.callback());
  line.finish();
  writeSegmentOutputs(dir, outcome, image, o.figures);
  printSummary(o, outcome, image);
}

}  // namespace

void addSegmentCommand(CLI::App& app) {
  auto o = std::make_shared<Arguments>();
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
                      "sphere:x,y,z,r (LPS mm), atlas (the atlas's structure --atlas-label registered to the image, "
                      "which also holds the surface softly where clicks and edges say nothing), or a closed "
                      "control mesh file in LPS mm")
      ->default_val("auto");
  command->add_option("--atlas-label", o->atlasLabel,
                      "With --init atlas: the structure's label value(s) in the atlas, or names from its table "
                      "(Caudate_L; Caudate_L,Caudate_R)");
  command->add_option("--atlas", o->atlas, "With --init atlas: the atlas's template image")
      ->default_str(kDefaultAtlasImage);
  command->add_option("--atlas-labels", o->atlasLabels,
                      "With --init atlas: the atlas's label map, on its template's grid, with its names in "
                      "LABELS.txt beside it (mricron's format: one 'VALUE NAME' per line)")
      ->default_str(kDefaultAtlasLabels);
  command->add_option("--inside", o->inside,
                      "With --init atlas: x,y,z (LPS mm), a click inside the structure; it picks the carried "
                      "label's part and moves a misplaced one there");
  command->add_option("--reference", o->reference, "Reference labelmap on the image's grid, for Dice and distances");
  command->add_option("--reference-label", o->referenceLabels, "Label value(s) of the structure in --reference")
      ->delimiter(',');
  addSegmentParameterOptions(*command, o->parameters);
  o->figures.addOptions(*command);
  command->callback([o] { runSegment(*o); });
}

}  // namespace dynsub::app
