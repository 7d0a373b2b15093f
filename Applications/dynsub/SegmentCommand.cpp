// dynsub segment: a structure in a 3D image from image forces and expert landmarks (Segmentation.h).
#include <CLI/CLI.hpp>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <future>
#include <iomanip>
#include <iostream>
#include <memory>
#include <optional>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "CommandLine.h"
#include "Commands.h"
#include "EarlierRuns.h"
#include "FigureOutputs.h"
#include "LandmarkSources.h"
#include "dynsub/Atlas.h"
#include "dynsub/Error.h"
#include "dynsub/FileNames.h"
#include "dynsub/ImageIO.h"
#include "dynsub/Metrics.h"
#include "dynsub/ModelOutputs.h"
#include "dynsub/OutputSet.h"
#include "dynsub/ParallelFor.h"
#include "dynsub/SegmentImage.h"
#include "dynsub/SegmentStructures.h"
#include "dynsub/SurfaceWriter.h"
#include "dynsub/TextFields.h"

namespace dynsub::app {

namespace {

// What `dynsub segment` reads besides the parameters, and the parameters.
struct Arguments {
  std::string image;
  std::string out;
  // Landmark files: each holds one structure's points, or (a markups file)
  // a point list per structure. Several structures are segmented together.
  std::vector<std::string> landmarks;
  std::vector<std::string> names;  // one per structure, or none (landmarkSources' names)
  // Initial models: none (auto), one for the run, or one per structure: the
  // point lists' in their order, then the structures without landmarks.
  std::vector<std::string> init;
  std::string reference;
  std::vector<std::string> referenceLabels;  // "N[,M...]": one per structure
  std::string atlas = kDefaultAtlasImage;
  std::string atlasLabels = kDefaultAtlasLabels;
  std::vector<std::string> atlasLabel;  // with --init atlas: one structure's labels each
  std::vector<std::string> inside;      // with --init atlas: none, or one per atlas label
  SegmentParameters parameters;
  FigureOptions figures;
};

// "71", "71,72" or "Caudate_L": a structure's labels in --reference, by
// value or by name in the table beside it (Atlas.h's labelSpecValues). The
// table is read into `names` when a name is first given, and serves every
// structure of the run after that.
std::vector<int> parseLabelValues(const std::string& text, const std::string& reference,
                                  std::optional<LabelNames>& names) {
  return labelSpecValues(
      text, reference,
      [&]() -> const LabelNames& {
        if (!names) {
          requireExisting(reference);  // a missing reference, not a missing table
          names = readLabelNames(reference);
        }
        return *names;
      },
      "--reference-label");
}

// The expert's labelmap, on the image's grid.
Volume readReferenceLabels(const std::string& path, const Volume& image) {
  Volume labels = readLabelMap(path);
  if (const std::string difference = labels.geometry.differenceFrom(image.geometry, "image"); !difference.empty())
    throw Error(path, "the reference is not on the image's grid: " + difference + "; resample it onto that grid");
  return labels;
}

// One structure in the expert's labelmap.
Mask referenceStructure(const std::string& path, const Volume& labels, const std::vector<int>& values) {
  Mask reference = selectLabels(labels, values);
  if (reference.count() == 0) {
    std::string list;
    for (int value : values) list += (list.empty() ? "" : ",") + std::to_string(value);
    throw Error(path, "no voxel has the reference label(s) " + list);
  }
  return reference;
}

// surface.vtp, control_mesh.obj, report.json, labelmap.nii.gz, convergence.csv and the figures, all or none.
// What an earlier run into `dir` wrote that this one does not is retired (EarlierRuns.h).
void writeSegmentOutputs(const std::filesystem::path& dir, const SegmentOutcome& outcome, const Volume& image,
                         const FigureOptions& figures) {
  const SegmentResult& result = outcome.result;
  writeModelOutputs(
      dir, result.mesh, result.surface, outcome.report,
      [&](OutputSet& outputs) {
        retireEarlierRun(outputs, dir);
        const std::string labelmapPath = outputs.add(kLabelmapFile);
        const auto labelmap = [&] { writeMask(outcome.labelmap, labelmapPath); };
        const auto figuresAndRecord = [&] {
          FigureInputs inputs;
          inputs.surface = &result.surface;
          inputs.image = &image;
          inputs.landmarks = landmarkPositions(outcome.springs);
          inputs.history = &outcome.history;
          inputs.edgeDistances = result.surfaceEdgeDistances;
          addFigureOutputs(outputs, figures, result.mesh, std::move(inputs));
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
  std::cout << std::fixed << std::setprecision(1) << "segmented "
            << outcome.labelmap.count() * image.geometry.spacing.prod() << " mm^3 with " << result.mesh.vertexCount()
            << " control vertices (" << result.levels.back().level << " refinement(s), " << result.steps
            << " steps) in " << outcome.seconds << " s\n";
  const std::string carried = carriedPastSlices(outcome.result);
  // An atlas start without clicks marches from its own points' slices.
  if (!carried.empty() && outcome.carried && o.landmarks.empty())
    std::cout << "followed the structure's tissue past the ends of the atlas's structure and pulled the surface "
                 "there: "
              << carried << " (--slice-ends false to keep to the atlas's ends)\n";
  else if (!carried.empty())
    std::cout << "followed the structure's tissue past the outermost clicked slices and pulled the surface there: "
              << carried << " (--slice-ends false if your clicks already reach its ends)\n";
  for (const std::string& warning : outcome.warnings) std::cerr << "warning: " << warning << '\n';
  for (const TrustFlag& flag : outcome.trustFlags)
    std::cerr << "not to trust (" << flag.name << "): " << flag.message << '\n';
  if (!o.reference.empty())
    std::cout << std::setprecision(3) << "Dice " << outcome.metrics.dice << ", mean surface distance "
              << outcome.metrics.meanSurfaceDistance << " mm, HD95 " << outcome.metrics.hd95 << " mm against "
              << o.reference << '\n';
  std::cout << "wrote " << (std::filesystem::path(o.out) / kSurfaceFile).string()
            << ", control_mesh.obj, labelmap.nii.gz, report.json, convergence.csv"
            << (o.figures.figures ? " and the figures that could be rendered" : "") << '\n';
}

// The start given first, or the default (auto) when --init is not given.
std::string firstStart(const Arguments& o) { return o.init.empty() ? "auto" : o.init.front(); }

// `landmarks`: the one structure's, or null (no --landmarks).
void runSegmentOne(const Arguments& o, const LandmarkSource* landmarks) {
  // Every input is read and checked before anything is written.
  if (!o.reference.empty() && o.referenceLabels.empty())
    throw UsageError("--reference needs --reference-label N[,M...]: the label value(s) or name(s) of the structure");
  if (o.inside.size() > 1)
    throw UsageError("--inside is given " + std::to_string(o.inside.size()) +
                     " times for one structure: give one click inside it");
  if (o.names.size() > 1)
    throw UsageError("--name is given " + std::to_string(o.names.size()) +
                     " times for one structure: name each structure segmented together once, or none");
  SegmentInputs inputs;
  inputs.start = parseSegmentStart(firstStart(o), "--init");
  // One structure's values, as N[,M...] or as several values (71 72).
  std::vector<int> referenceLabels;
  std::optional<LabelNames> referenceNames;
  for (const std::string& values : o.referenceLabels)
    for (const int value : parseLabelValues(values, o.reference, referenceNames)) referenceLabels.push_back(value);
  const std::filesystem::path dir(o.out);
  requireInputsOutsideRun(dir, {o.image, landmarks ? landmarks->path : "", o.reference, o.atlas, o.atlasLabels});
  const Volume image = readVolume(o.image);
  // The reference is needed only to score the result, and reading it
  // (a whole labelmap, inflated and converted) took a fifth of the caudate
  // demo's command: it is read on a second thread while the atlas is read
  // and the segmentation runs, and its errors (a missing file at once) still
  // come before any output is written.
  std::shared_future<Mask> reference;
  // The thread reads `image` and `referenceLabels`: whatever ends this run,
  // an error included, it ends before they are destroyed (`inputs`, declared
  // before them, keeps a copy of the future).
  struct WaitForReference {
    const std::shared_future<Mask>& future;
    ~WaitForReference() {
      if (future.valid()) future.wait();
    }
  } waitForReference{reference};
  if (!o.reference.empty()) {
    requireExisting(o.reference);  // before the segmentation; its other errors come with its reading
    reference = std::async(std::launch::async, [&o, &image, &referenceLabels] {
                  return referenceStructure(o.reference, readReferenceLabels(o.reference, image), referenceLabels);
                }).share();
    inputs.reference = [reference]() -> const Mask& { return reference.get(); };
    inputs.referencePath = o.reference;
    inputs.referenceLabels = referenceLabels;
  }
  if (landmarks) {
    inputs.landmarks = landmarks->list.landmarks;
    inputs.landmarkSystem = landmarks->list.stated;
    inputs.landmarkSource = landmarks->path;
  }
  inputs.image = o.image;
  if (!o.inside.empty()) inputs.inside = parsePoint(o.inside.front(), "--inside");
  if (inputs.start.kind == SegmentStart::Kind::Atlas) {
    if (o.atlasLabel.empty())
      throw UsageError("--init atlas needs --atlas-label N[,M...] or a name from the atlas's table (e.g. Caudate_L)");
    inputs.atlas = std::make_shared<const Atlas>(readAtlas(o.atlas, o.atlasLabels));
    inputs.atlasLabels = atlasLabelValues(*inputs.atlas, o.atlasLabel.front());
  } else if (!o.atlasLabel.empty()) {
    throw UsageError("--atlas-label serves an atlas start: add --init atlas");
  }
  checkSegmentInputs(inputs, o.parameters);
  // An atlas start registers for seconds first: a reference that cannot
  // score the result (another grid, no such label) is refused before that.
  if (reference.valid() && inputs.start.kind == SegmentStart::Kind::Atlas) reference.get();
  prepareOutputDirectory(dir);
  o.figures.prepare();

  ProgressLine line;
  const SegmentOutcome outcome = segmentImage(image, inputs, o.parameters, line.callback());
  line.finish();
  writeSegmentOutputs(dir, outcome, image, o.figures);
  printSummary(o, outcome, image);
}

// BIDS's table of a dseg's labels: index, name and a colour (structureColor)
// for viewers that take one.
void writeLabelTable(const std::vector<StructureInputs>& structures, const std::string& path) {
  std::ofstream table(path);
  table << "index\tname\tcolor\n";
  for (std::size_t s = 0; s < structures.size(); ++s) {
    const std::array<std::uint8_t, 3> rgb = structureColor(s);
    char hex[8];
    std::snprintf(hex, sizeof hex, "#%02x%02x%02x", rgb[0], rgb[1], rgb[2]);
    table << s + 1 << '\t' << structures[s].name << '\t' << hex << '\n';
  }
  table.close();
  if (!table) throw Error(path, "could not be written");
}

// Several structures: each in DIR/NAME as one structure's run writes it, then
// DIR/dseg.nii.gz, DIR/dseg.tsv and DIR/report.json, the run's report, last:
// it is there only when everything is.
void runSegmentTogether(const Arguments& o, const std::vector<LandmarkSource>& sources) {
  // The structures: the landmarks' lists, or with --init atlas the atlas
  // labels, each paired with its list when --landmarks are given too. An
  // --init per structure starts each from its own model (a seed click, say):
  // the lists' in their order, then any further structures without
  // landmarks.
  const std::string first = firstStart(o);
  const bool atlas = first == "atlas";
  const bool each = o.init.size() > 1;
  if (each) {
    for (const std::string& start : o.init)
      if (start == "atlas")
        throw UsageError(
            "--init atlas starts every structure from the atlas: give it once, with an --atlas-label per "
            "structure");
  } else if (!atlas && first != "auto") {
    throw UsageError("--init " + first +
                     ": give an --init per structure (the point lists' in their order, then any "
                     "structures without landmarks), or start them all from their landmarks (auto) or from the atlas "
                     "(--init atlas, an --atlas-label per structure)");
  }
  if (!atlas && !o.atlasLabel.empty()) throw UsageError("--atlas-label serves an atlas start: add --init atlas");
  const std::size_t n = atlas ? o.atlasLabel.size() : std::max(sources.size(), o.init.size());
  if (atlas && !sources.empty() && sources.size() != n)
    throw UsageError("--init atlas with --landmarks: give an --atlas-label per point list, in their order (" +
                     std::to_string(sources.size()) + " lists, " + std::to_string(n) + " atlas labels)");
  if (each && o.init.size() < sources.size())
    throw UsageError("--init is given " + std::to_string(o.init.size()) + " times for " +
                     std::to_string(sources.size()) + " point lists: give one per structure, or one for all");
  if (!atlas && !o.inside.empty())
    throw UsageError(
        "--inside serves an atlas start (--init atlas); to start a structure from one click alone, give "
        "it --init seed:x,y,z");
  if (!o.inside.empty() && o.inside.size() != n)
    throw UsageError("--inside is given " + std::to_string(o.inside.size()) + " times for " + std::to_string(n) +
                     " atlas structures: give a click inside each, in the order of --atlas-label, or none");
  if (!atlas && sources.size() < n && o.names.empty())
    throw UsageError("structures without landmarks need names: give a --name per structure, in the order of --init");
  const std::string order = atlas ? "--atlas-label" : each ? "--init" : "--landmarks";
  if (!o.names.empty() && o.names.size() != n)
    throw UsageError("--name is given " + std::to_string(o.names.size()) + " times for " + std::to_string(n) +
                     " structures (one per " + order + "): name each structure, or none");
  for (const std::string& name : o.names)
    if (std::count(o.names.begin(), o.names.end(), name) > 1)
      throw UsageError("--name " + name + " is given twice: name each structure once");
  if (!o.reference.empty() && o.referenceLabels.size() != n)
    throw UsageError("--reference needs one --reference-label N[,M...] per structure, in the order of " + order + " (" +
                     std::to_string(n) + " structures, " + std::to_string(o.referenceLabels.size()) + " given)");
  const std::shared_ptr<const Atlas> atlasData =
      atlas ? std::make_shared<const Atlas>(readAtlas(o.atlas, o.atlasLabels)) : nullptr;
  std::vector<StructureInputs> structures =
      structuresToSegment(o.image, sources, atlasData, o.atlasLabel, "--atlas-label");
  structures.resize(n);  // those without landmarks after the lists
  std::optional<LabelNames> referenceNames;
  for (std::size_t s = 0; s < n; ++s) {
    StructureInputs& structure = structures[s];
    SegmentInputs& in = structure.inputs;
    in.image = o.image;
    if (each) in.start = parseSegmentStart(o.init[s], "--init");
    if (!o.inside.empty()) in.inside = parsePoint(o.inside[s], "--inside");
    if (!o.names.empty()) structure.name = o.names[s];
    if (!o.reference.empty()) {
      in.referencePath = o.reference;
      in.referenceLabels = parseLabelValues(o.referenceLabels[s], o.reference, referenceNames);
    }
  }
  const Volume image = readVolume(o.image);
  checkStructures(structures, o.parameters);
  // A structure's folder in DIR must not take the name of a file the run
  // writes or removes there.
  const std::vector<std::string> files = runFiles();
  for (const StructureInputs& structure : structures)
    if (std::find(files.begin(), files.end(), structure.name) != files.end())
      throw UsageError("structure name '" + structure.name + "' is a file the run writes or removes in " + o.out +
                       ": give the structure another --name");
  // The references: one labelmap, read once, each structure's labels picked
  // from it before the run.
  std::vector<std::optional<Mask>> references(structures.size());
  if (!o.reference.empty()) {
    const Volume labels = readReferenceLabels(o.reference, image);
    for (std::size_t s = 0; s < structures.size(); ++s) {
      references[s] = referenceStructure(o.reference, labels, structures[s].inputs.referenceLabels);
      structures[s].inputs.reference = [&references, s]() -> const Mask& { return *references[s]; };
    }
  }
  const std::filesystem::path dir(o.out);
  std::vector<std::string> inputs{o.image, o.reference, o.atlas, o.atlasLabels};
  for (const LandmarkSource& source : sources) inputs.push_back(source.path);
  std::vector<std::string> names;
  for (const StructureInputs& structure : structures) names.push_back(structure.name);
  requireInputsOutsideRun(dir, inputs, names);
  for (const std::string& name : names) requireInputsOutsideRun(dir / name, inputs);
  prepareOutputDirectory(dir);
  o.figures.prepare();

  ProgressLine line;
  const StructuresOutcome outcome = segmentStructures(image, structures, o.parameters, line.callback());
  line.finish();
  // The structures' folders are written into the run's set: a new DIR
  // appears whole, with them. Into a DIR that exists, each structure's set
  // commits on its own; should a later one fail, the folders this run made
  // are removed again, so that nothing of it is left half-written.
  std::vector<std::filesystem::path> made;
  try {
    OutputSet outputs(dir);
    for (std::size_t s = 0; s < structures.size(); ++s) {
      const std::filesystem::path own = outputs.writingDirectory() / structures[s].name;
      if (outputs.writingDirectory() == dir && !std::filesystem::exists(own)) made.push_back(own);
      writeSegmentOutputs(own, outcome.structures[s], image, o.figures);
    }
    // What an earlier run into DIR wrote that this one does not: one
    // structure's outputs, a fit's, or other structures' folders.
    retireEarlierRun(outputs, dir, names);
    writeVolume(outcome.labels, outputs.add(kJoinedLabelmap), VoxelType::Label16);
    writeLabelTable(structures, outputs.add(kJoinedTable));
    outcome.report.write(outputs.add(kReportFile));
    outputs.commit();
  } catch (...) {
    std::error_code ignored;
    for (auto it = made.rbegin(); it != made.rend(); ++it) std::filesystem::remove_all(*it, ignored);
    throw;
  }

  std::cout << std::fixed << std::setprecision(1) << "segmented " << structures.size() << " structures together in "
            << outcome.seconds << " s; voxels in two structures: " << outcome.sharedAlone << " alone, "
            << outcome.sharedTogether << " with the barrier, 0 in dseg.nii.gz\n";
  for (std::size_t s = 0; s < structures.size(); ++s) {
    const SegmentOutcome& one = outcome.structures[s];
    std::cout << std::setprecision(1) << "  " << s + 1 << " " << structures[s].name << ": "
              << static_cast<double>(one.labelmap.count()) * image.geometry.spacing.prod() << " mm^3"
              << (outcome.segmentedAgain[s] ? ", segmented again against the others" : "");
    if (references[s])
      std::cout << std::setprecision(3) << ", Dice " << outcome.aloneMetrics[s].dice << " alone, "
                << outcome.jointMetrics[s].dice << " in dseg";
    std::cout << '\n';
    for (const std::string& warning : one.warnings)
      std::cerr << "warning (" << structures[s].name << "): " << warning << '\n';
    for (const TrustFlag& flag : one.trustFlags)
      std::cerr << "not to trust (" << structures[s].name << ", " << flag.name << "): " << flag.message << '\n';
  }
  std::cout << "wrote " << (dir / kJoinedLabelmap).string() << ", dseg.tsv, report.json and a folder per structure\n";
}

void runSegment(const Arguments& o) {
  const std::vector<LandmarkSource> sources = landmarkSources(o.landmarks);
  if (sources.size() > 1 || o.atlasLabel.size() > 1 || o.init.size() > 1)
    runSegmentTogether(o, sources);
  else
    runSegmentOne(o, sources.empty() ? nullptr : &sources.front());
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
      "DIR/convergence.png (or .pdf, .svg: --figure-format).");
  command->add_option("IMAGE", o->image, "3D image: .nii/.nii.gz, .nrrd, .mha/.mhd, or a DICOM series directory")
      ->required();
  command->add_option("--out", o->out, "Output directory (created if missing; its parent must exist)")->required();
  command
      ->add_option("--landmarks", o->landmarks,
                   "Boundary points: .mrk.json, .fcsv or .csv (x,y,z or l,p,s in LPS mm; r,a,s in RAS). Given "
                   "once per structure, or as a .mrk.json with a point list per structure, the structures are "
                   "segmented together: they "
                   "do not overlap, and DIR/dseg.nii.gz with DIR/dseg.tsv names them (each structure's outputs "
                   "in DIR/NAME)")
      ->expected(1)
      ->multi_option_policy(CLI::MultiOptionPolicy::TakeAll);
  command
      ->add_option("--name", o->names,
                   "With several structures: each one's name, in their order (default: the files' stems, a "
                   "markups file's list names, or the atlas labels)")
      ->expected(1)
      ->multi_option_policy(CLI::MultiOptionPolicy::TakeAll);
  command
      ->add_option("--init", o->init,
                   "Initial model: auto (the 98-vertex cube inside the landmarks' PCA ellipsoid), "
                   "seed:x,y,z (one click inside the structure, LPS mm: grown through the tissue like the "
                   "click's, its boundary the springs when no --landmarks are given), "
                   "sphere:x,y,z,r (LPS mm), atlas (the atlas's structure --atlas-label registered to the image, "
                   "which also holds the surface softly where clicks and edges say nothing), or a closed "
                   "control mesh file in LPS mm (default auto). With several structures: once for all (auto or "
                   "atlas), or once per structure (not atlas), the point lists' in their order, then structures "
                   "without landmarks (each named by --name)")
      ->expected(1)
      ->multi_option_policy(CLI::MultiOptionPolicy::TakeAll);
  command
      ->add_option("--atlas-label", o->atlasLabel,
                   "With --init atlas: the structure's label value(s) in the atlas, or names from its table "
                   "(Caudate_L, or labels that touch: Putamen_L,Pallidum_L). Given once per structure, the structures "
                   "are segmented together (with --landmarks, one per point list, in their order)")
      ->expected(1)
      ->multi_option_policy(CLI::MultiOptionPolicy::TakeAll);
  command->add_option("--atlas", o->atlas, "With --init atlas: the atlas's template image")
      ->default_str(kDefaultAtlasImage);
  command
      ->add_option("--atlas-labels", o->atlasLabels,
                   "With --init atlas: the atlas's label map, on its template's grid, with its names in "
                   "LABELS.txt beside it (mricron's format: one 'VALUE NAME' per line)")
      ->default_str(kDefaultAtlasLabels);
  command
      ->add_option("--inside", o->inside,
                   "With --init atlas: x,y,z (LPS mm), a click inside the structure; it picks the carried label's "
                   "part and moves a misplaced one there. With several atlas structures, once per --atlas-label")
      ->expected(1)
      ->multi_option_policy(CLI::MultiOptionPolicy::TakeAll);
  CLI::Option* reference = command->add_option("--reference", o->reference,
                                               "Reference labelmap on the image's grid, for Dice and distances");
  command
      ->add_option(
          "--reference-label", o->referenceLabels,
          "Label value(s) of the structure in --reference, N[,M...], or names in the table beside it "
          "(REF.nii.txt, REF.txt or a BIDS REF.tsv for REF.nii.gz); with several --landmarks, once per structure in "
          "their order")
      ->expected(1)
      ->multi_option_policy(CLI::MultiOptionPolicy::TakeAll)
      ->needs(reference);
  addSegmentParameterOptions(*command, o->parameters);
  o->figures.addOptions(*command);
  command->callback([o] { runSegment(*o); });
}

}  // namespace dynsub::app
