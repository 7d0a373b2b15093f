// DynSubSegment: `dynsub segment` as a 3D Slicer CLI module (Slicer
// Execution Model). Slicer runs `DynSubSegment --xml` to build the module's
// panel, then runs it with the data as files (the volume as .nrrd, the
// result as the label image and .vtp model it asks for) and each markups
// point as one `--seed x,y,z` in LPS mm. Progress goes to stdout as
// <filter-progress> tags, which Slicer shows as the module's progress bar.
// A points file with several lists (a markups file with one list per
// structure) segments the structures together, as `dynsub segment` does:
// one labelmap, one model and one segmentation (.seg.nrrd) hold them all.
//
// Exit codes: 0 success; 1 an error in the inputs or the run (stderr names the
// file and the problem, and nothing is written); 2 a usage error.
#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <iomanip>
#include <functional>
#include <iostream>
#include <list>
#include <memory>
#include <new>
#include <sstream>

#include <CLI/CLI.hpp>

#include "CommandLine.h"
#include "ExecutionModel.h"
#include "LandmarkSources.h"
#include "dynsub/AtomicOutput.h"
#include "dynsub/Error.h"
#include "dynsub/FileNames.h"
#include "dynsub/ImageIO.h"
#include "dynsub/Landmarks.h"
#include "dynsub/SegmentImage.h"
#include "dynsub/SegmentStructures.h"
#include "dynsub/SurfaceWriter.h"
#include "dynsub/TextFields.h"

namespace {

using namespace dynsub;
using dynsub::app::LandmarkSource;
using dynsub::app::landmarkSources;
using dynsub::app::structuresToSegment;

struct Arguments {
  std::string image, landmarks, inside, atlasLabel, labelmap, model, segmentation, report;
  std::vector<std::string> seeds;
  int labelValue = 1;
  SegmentParameters parameters;
  // What Slicer passes for the table's choices and for its switches that are
  // on by default (as their opposites), given to `parameters` after parsing.
  std::list<std::string> choices;
  std::list<bool> opposites;
  std::vector<std::function<void(Arguments&)>> afterParsing;
};

// The table's rows (SegmentParameters.h) as the panel's parameters, in the
// table's groups. Slicer has no unset number, so the optional ones (the edge
// thresholds, whose default depends on the reference) are left to `dynsub
// segment`.
std::vector<slicer::ParameterGroup> parameterGroups(Arguments& a) {
  std::vector<slicer::ParameterGroup> groups;
  for (const dynsub::ParameterGroup& g : segmentParameterGroups()) {
    slicer::ParameterGroup group{g.name, g.help, g.advanced, {}};
    for (const dynsub::Parameter& row : segmentParameters()) {
      if (row.group != g.name) continue;
      const std::string label = row.label + (row.unit.empty() ? "" : " (" + row.unit + ")");
      slicer::Parameter p{"", "", row.camelName(), row.camelName(), label, row.help + ".", {}, "", "", "", "", {}, -1};
      // A number's range and slider step; an unbounded end is left out.
      const auto constrain = [&] {
        const auto bound = [](double v) { return std::isfinite(v) ? slicer::number(v) : std::string(); };
        p.minimum = bound(row.low);
        p.maximum = bound(row.high);
        p.step = row.step > 0 ? slicer::number(row.step) : "";
      };
      if (const auto* real = std::get_if<dynsub::Parameter::Real>(&row.value)) {
        p.element = "double";
        p.target = &(*real)(a.parameters);
        constrain();
      } else if (const auto* whole = std::get_if<dynsub::Parameter::Whole>(&row.value)) {
        p.element = "integer";
        p.target = &(*whole)(a.parameters);
        constrain();
      } else if (const auto* choice = std::get_if<dynsub::Parameter::Choice>(&row.value)) {
        p.element = "string-enumeration";
        p.choices = choice->names;
        std::string& value = a.choices.emplace_back(choice->get(a.parameters));
        p.target = &value;
        a.afterParsing.push_back([set = choice->set, &value](Arguments& arguments) { set(arguments.parameters, value); });
      } else if (const auto* on = std::get_if<dynsub::Parameter::Switch>(&row.value)) {
        p.element = "boolean";
        if (!(*on)(a.parameters)) {
          p.target = &(*on)(a.parameters);
        } else {
          // On by default: Slicer can only switch on, so the panel offers its opposite.
          p.name = p.flag = row.opposite->name;
          p.label = row.opposite->label;
          p.description = row.opposite->help;
          bool& opposite = a.opposites.emplace_back(false);
          p.target = &opposite;
          a.afterParsing.push_back([access = *on, &opposite](Arguments& arguments) {
            access(arguments.parameters) = !opposite;
          });
        }
      } else {
        continue;  // an optional number
      }
      group.parameters.push_back(p);
    }
    groups.push_back(group);
  }
  return groups;
}

slicer::Module describe(Arguments& a) {
  slicer::Module m;
  m.category = "Segmentation";
  m.title = "DynSub Segment";
  m.description =
      "Segments a structure with a dynamic Catmull-Clark subdivision surface: a smooth closed surface, defined by "
      "a small control mesh, moves toward the image's edges and toward points placed on the structure's boundary, "
      "and is refined until it meets them. Give at least 4 boundary points, one point inside the structure "
      "(its tissue is grown from there and the surface starts on that region's boundary), or the structure's "
      "name in the AAL atlas.";
  m.version = DYNSUB_VERSION;
  m.documentationUrl = DYNSUB_DOCUMENTATION_URL;
  m.license = "See the DynSub source tree";
  m.contributor = "DynSub developers";
  m.acknowledgements = "Built on ITK, VTK and Eigen.";

  slicer::ParameterGroup io{"Input and output", "The volume, the points, and what is written.", false, {}};
  io.parameters.push_back({"image", "type=\"scalar\"", "inputVolume", "", "Input volume",
                           "The 3D image to segment (an MRI, for example).", &a.image, "input", "", "", "", {}, 0});
  io.parameters.push_back({"point", "multiple=\"true\" coordinateSystem=\"lps\"", "seed", "seed", "Boundary points",
                           "Points on the structure's boundary, at least 4 (a few per slice on several slices is "
                           "typical). A single point is taken as a click inside the structure.",
                           &a.seeds, "", "", "", "", {}, -1});
  io.parameters.push_back({"file", "fileExtensions=\".mrk.json,.fcsv,.csv\"", "landmarksFile", "landmarks",
                           "Boundary points file",
                           "Boundary points from a file (.mrk.json, .fcsv, or .csv with x,y,z columns in LPS mm), "
                           "added to the points above. A markups file with several point lists is several "
                           "structures, segmented together so that they do not overlap, each named by its list.",
                           &a.landmarks, "input", "", "", "", {}, -1});
  io.parameters.push_back({"point", "coordinateSystem=\"lps\"", "inside", "inside", "Point inside",
                           "One click inside the structure: the surface starts from the region of like tissue "
                           "grown from it. Without boundary points that region's boundary guides the surface.",
                           &a.inside, "", "", "", "", {}, -1});
  io.parameters.push_back({"string", "", "atlasLabel", "atlasLabel", "Atlas structure",
                           "The structure's label value(s) or name(s) in Colin27's AAL atlas (Caudate_L, or "
                           "Putamen_L,Pallidum_L, labels that touch): the atlas, registered to the volume, starts "
                           "the surface and holds it softly where the points and the edges say nothing. The point "
                           "inside, if given, says where the structure is. Several structures, separated by ';' "
                           "(Caudate_L;Putamen_L), are segmented together, each paired in order with a list "
                           "of the points file when it has several.",
                           &a.atlasLabel, "", "", "", "", {}, -1});
  io.parameters.push_back({"image", "type=\"label\" reference=\"inputVolume\"", "outputLabelmap", "labelmap",
                           "Output labelmap", "The structure as a label image on the input volume's grid.",
                           &a.labelmap, "output", "", "", "", {}, -1});
  // nipype names an output it is asked for by the first extension declared.
  std::string modelExtensions;
  for (const std::string& e : triangleSurfaceExtensions()) modelExtensions += (modelExtensions.empty() ? "" : ",") + e;
  io.parameters.push_back({"geometry", "type=\"model\" fileExtensions=\"" + modelExtensions + "\"", "outputModel",
                           "model", "Output model", "The fitted limit surface as a triangle model (LPS mm).",
                           &a.model, "output", "", "", "", {}, -1});
  io.parameters.push_back({"file", "fileExtensions=\".seg.nrrd\"", "outputSegmentation", "segmentation",
                           "Output segmentation",
                           "Optional: the structures as a 3D Slicer segmentation (.seg.nrrd), with their names and "
                           "colours; load it with Add Data.",
                           &a.segmentation, "output", "", "", "", {}, -1});
  io.parameters.push_back({"file", "fileExtensions=\".json\"", "report", "report", "Report",
                           "Optional: the run's numbers and warnings as JSON (the report.json of dynsub segment).",
                           &a.report, "output", "", "", "", {}, -1});
  io.parameters.push_back({"integer", "", "labelValue", "labelValue", "Label value",
                           "The structure's value in the output labelmap (Slicer colours it by this value); "
                           "of several structures, the first's, and the next ones' count up from it.",
                           &a.labelValue, "", "1", "255", "1", {}, -1});

  m.groups = {io};
  for (slicer::ParameterGroup& group : parameterGroups(a)) m.groups.push_back(group);
  return m;
}

// Slicer's progress bar: <filter-progress> from 0 to 1, each of the
// structures' segmentations an equal share of the evolution's and each
// level of one an equal share of that (a level's steps approach its end).
// Structures segmented again against the others stay in the last share.
class SlicerProgress {
 public:
  explicit SlicerProgress(int levels) : levels_(levels) {}
  void setStructures(int structures) { structures_ = structures; }
  void stage(double fraction, const std::string& comment) {
    std::cout << "<filter-comment>" << comment << "</filter-comment>\n";
    report(fraction);
  }
  ProgressCallback callback() {
    return [this](const Progress& p) {
      if (p.level == 0 && p.step == 1) started_ = std::min(started_ + 1, structures_);  // a segmentation begins
      const double withinLevel = 1.0 - 1.0 / (1.0 + p.step / 50.0);
      const double withinRun = (std::min(p.level, levels_ - 1) + withinLevel) / levels_;
      report(0.1 + 0.8 * (std::max(started_ - 1, 0) + withinRun) / structures_);
    };
  }
  void report(double fraction) {
    if (fraction < last_ + 0.01 && fraction < 1.0) return;
    last_ = fraction;
    std::cout << "<filter-progress>" << std::fixed << std::setprecision(2) << fraction << "</filter-progress>"
              << std::endl;
  }

 private:
  int levels_;
  int structures_ = 1, started_ = 0;
  double last_ = -1;
};

// An output's name is the user's to fix, before anything runs. ".gz" is
// read with the extension before it (.nii.gz), so that "x.gz" is not
// taken for a compressed NIfTI file.
void requireExtension(const std::string& path, const std::vector<std::string>& known, const std::string& what) {
  std::string extension = lowerCaseExtension(path);
  if (extension == ".gz") extension = lowerCaseExtension(std::filesystem::path(path).stem().string()) + extension;
  for (const std::string& k : known)
    if (extension == k) return;
  throw UsageError(path, "unknown " + what + " format '" + extension + "' (expected " + joined(known, ", ") + ")");
}

// A structure's segment in the .seg.nrrd: its label value, its name (a
// markups list's may hold control characters, which become spaces) and its
// colour (structureColor, as dynsub segment's dseg.tsv gives it).
SlicerSegment segmentOf(int label, const std::string& name, std::size_t index) {
  const std::array<std::uint8_t, 3> rgb = structureColor(index);
  std::string shown = name;
  std::replace_if(
      shown.begin(), shown.end(), [](unsigned char c) { return c < 0x20 || c == 0x7f; }, ' ');
  return {label, shown, {rgb[0] / 255.0, rgb[1] / 255.0, rgb[2] / 255.0}};
}

// What a run writes, all together or none. `writeLabels(labelmap,
// segmentation)` writes the structures' voxels to the temporary paths it is
// given (empty where that output was not asked for); the model and the
// report are written here.
void writeOutputs(const Arguments& a, const std::function<void(const std::string&, const std::string&)>& writeLabels,
                  const TriangleSurface& surface, const std::vector<PointScalars>& scalars, const Report& report) {
  std::vector<std::unique_ptr<AtomicOutput>> outputs;
  const auto add = [&outputs](const std::string& path) {
    if (path.empty()) return std::string();
    outputs.push_back(std::make_unique<AtomicOutput>(path));
    return outputs.back()->temporaryPath();
  };
  const std::string labelmap = add(a.labelmap);
  writeLabels(labelmap, add(a.segmentation));
  if (!a.model.empty()) writeTriangleSurface(surface, add(a.model), scalars, "LPS");
  if (!a.report.empty()) report.write(add(a.report));
  for (auto& output : outputs) output->commit();
}

// The library's messages name dynsub segment's options; the module's are
// made from the same parameter table (camelCase, a switch's opposite), and a
// few others are its own.
std::string inModuleTerms(std::string message) {
  std::vector<std::pair<std::string, std::string>> terms = {
      {"--init atlas --inside", "--atlasLabel with --inside"},
      {"--init seed:x,y,z", "--inside x,y,z"},
      {"--init atlas", "--atlasLabel"},
      {"--atlas-label", "--atlasLabel"},
      {"give each structure a --name", "give each point list a name of its own"},
      {"give each structure an --atlas-label of its own", "separate the structures' labels with ';'"}};
  for (const Parameter& row : segmentParameters()) {
    if (row.opposite)
      terms.emplace_back(row.flag() + " false", "--" + row.opposite->name);
    else
      terms.emplace_back(row.flag(), "--" + row.camelName());
  }
  // The longest first, so that no flag is taken for the start of another.
  std::stable_sort(terms.begin(), terms.end(),
                   [](const auto& a, const auto& b) { return a.first.size() > b.first.size(); });
  for (const auto& [from, to] : terms) {
    for (std::size_t at = message.find(from); at != std::string::npos; at = message.find(from, at)) {
      const std::size_t end = at + from.size();
      const bool whole = end == message.size() || !(std::isalnum(static_cast<unsigned char>(message[end])) ||
                                                    message[end] == '-' || message[end] == '_');
      if (!whole) {
        at = end;
        continue;
      }
      message.replace(at, from.size(), to);
      at += to.size();
    }
  }
  return message;
}

void reportWarnings(const SegmentOutcome& outcome, const std::string& structure) {
  const std::string of = structure.empty() ? "" : structure + ", ";
  for (const std::string& warning : outcome.warnings)
    std::cerr << "warning" << (structure.empty() ? "" : " (" + structure + ")") << ": " << inModuleTerms(warning)
              << '\n';
  for (const dynsub::TrustFlag& flag : outcome.trustFlags)
    std::cerr << "not to trust (" << of << flag.name << "): " << inModuleTerms(flag.message) << '\n';
}

// One point cannot outline a structure: it is read as a click inside it, the
// structure's seed start. `from` says where the point came from, for the report.
void startFromTheOnePoint(SegmentInputs& in, const std::string& from) {
  in.start.kind = SegmentStart::Kind::Seed;
  in.start.center = in.landmarks.front().position;
  in.start.text = "inside:" + from;
  in.landmarks.clear();
}

// One structure: from the points, the file's one list, a click inside, or
// the atlas.
void runOne(Arguments& a, const Volume& image, const LandmarkSource* file, SlicerProgress& progress) {
  SegmentInputs in;
  in.image = a.image;
  for (std::size_t i = 0; i < a.seeds.size(); ++i)
    in.landmarks.push_back({"seed-" + std::to_string(i + 1), parsePoint(a.seeds[i], "--seed")});
  in.landmarkSource = "--seed";
  if (file) {
    in.landmarkSystem = file->list.stated;
    in.landmarks.insert(in.landmarks.end(), file->list.landmarks.begin(), file->list.landmarks.end());
    in.landmarkSource = a.seeds.empty() ? a.landmarks : "--seed and " + a.landmarks;
  }
  if (!a.atlasLabel.empty()) {
    in.start = parseSegmentStart("atlas", "--init");
    in.atlas = std::make_shared<const Atlas>(readAtlas(kDefaultAtlasImage, kDefaultAtlasLabels));
    in.atlasLabels = atlasLabelValues(*in.atlas, a.atlasLabel, "--atlasLabel");
    if (!a.inside.empty()) in.inside = parsePoint(a.inside, "--inside");
  } else if (!a.inside.empty()) {
    in.start.kind = SegmentStart::Kind::Seed;
    in.start.center = parsePoint(a.inside, "--inside");
    in.start.text = "inside:" + a.inside;
  } else if (in.landmarks.size() == 1) {
    startFromTheOnePoint(in, a.seeds.empty() ? "the one point of " + a.landmarks : a.seeds.front());
  }
  checkSegmentInputs(in, a.parameters);

  progress.stage(0.05, "evolving the surface");
  const SegmentOutcome outcome = segmentImage(image, in, a.parameters, progress.callback());
  progress.stage(0.95, "writing the results");

  // The segment's name: the points list's, the file's, or the atlas's.
  std::string name = "structure";
  if (file)
    name = file->list.name.empty() ? file->name : file->list.name;
  else if (in.atlas)
    name = atlasStructureName(*in.atlas, in.atlasLabels, a.atlasLabel);
  std::vector<PointScalars> scalars;
  if (outcome.result.surfaceEdgeDistances.size())
    scalars.push_back({kEdgeDistanceScalars, outcome.result.surfaceEdgeDistances});
  const auto writeLabels = [&](const std::string& labelmap, const std::string& segmentation) {
    if (!labelmap.empty()) writeMask(outcome.labelmap, labelmap, static_cast<std::uint8_t>(a.labelValue));
    if (!segmentation.empty())
      writeSlicerSegmentation(outcome.labelmap, segmentOf(a.labelValue, name, 0), segmentation);
  };
  writeOutputs(a, writeLabels, outcome.result.surface, scalars, outcome.report);

  const double volume = outcome.labelmap.count() * image.geometry.spacing.prod();
  std::cout << std::fixed << std::setprecision(1) << "segmented " << volume << " mm^3 with "
            << outcome.result.mesh.vertexCount() << " control vertices in " << outcome.seconds << " s\n";
  const std::string carried = carriedPastSlices(outcome.result);
  if (!carried.empty())
    std::cout << "<filter-comment>followed the structure's tissue past the outermost slices with points and "
                 "pulled the surface there: "
              << carried << " (check Points reach both ends if your points already reach them)</filter-comment>\n";
  reportWarnings(outcome, "");
}

// Several structures segmented together (SegmentStructures.h): a points
// file's lists, or atlas labels ("Caudate_L;Putamen_L"), or both paired in
// order. Each starts from its own points or atlas label, so points given
// otherwise would be no structure's.
void runTogether(Arguments& a, const Volume& image, const std::vector<LandmarkSource>& files,
                 const std::vector<std::string>& atlasLabels, SlicerProgress& progress) {
  const bool atlas = !atlasLabels.empty();
  const std::size_t n = atlas ? atlasLabels.size() : files.size();
  const std::string several = std::to_string(n) + " structures, segmented together from their own " +
                              (atlas ? "atlas labels" : "points") + ": ";
  if (atlas && !files.empty() && files.size() != n)
    throw UsageError(several + a.landmarks + " holds " + std::to_string(files.size()) +
                     " lists of points; give one atlas label per list, in their order (separated by ';')");
  if (!a.seeds.empty()) throw UsageError(several + "add boundary points to the lists of a points file, not as --seed");
  if (!a.inside.empty()) throw UsageError(several + "a point inside is one structure's; leave it out");
  const int lastLabel = a.labelValue + static_cast<int>(n) - 1;
  if (lastLabel > 255)
    throw UsageError(several + "their label values " + std::to_string(a.labelValue) + "-" + std::to_string(lastLabel) +
                     " pass 255; give a smaller --labelValue");
  const std::shared_ptr<const Atlas> atlasData =
      atlas ? std::make_shared<const Atlas>(readAtlas(kDefaultAtlasImage, kDefaultAtlasLabels)) : nullptr;
  std::vector<StructureInputs> structures = structuresToSegment(a.image, files, atlasData, atlasLabels, "--atlasLabel");
  // A list of one point is a click inside its structure, as one point is for
  // one structure: the start of a structure without an atlas label, the click
  // that places its atlas label otherwise.
  for (StructureInputs& structure : structures) {
    SegmentInputs& in = structure.inputs;
    if (in.landmarks.size() != 1) continue;
    if (in.atlas) {
      in.inside = in.landmarks.front().position;
      in.landmarks.clear();
    } else {
      startFromTheOnePoint(in, "the one point of " + structure.name);
    }
  }
  // The segments' names: the lists' own ("Caudate L"), else the atlas's.
  std::vector<std::string> names;
  for (std::size_t s = 0; s < n; ++s) {
    if (files.empty())
      names.push_back(atlasStructureName(*atlasData, structures[s].inputs.atlasLabels, atlasLabels[s]));
    else
      names.push_back(files[s].list.name.empty() ? files[s].name : files[s].list.name);
  }
  checkStructures(structures, a.parameters);

  progress.stage(0.05, "evolving the surfaces");
  const StructuresOutcome outcome = segmentStructures(image, structures, a.parameters, progress.callback());
  progress.stage(0.95, "writing the results");

  Volume labels = outcome.labels;
  for (float& v : labels.voxels)
    if (v != 0) v += a.labelValue - 1;
  std::vector<SlicerSegment> segments;
  // One model of all the surfaces; its point data "label" says whose each
  // point is, and the edge distances are kept where every surface has them.
  TriangleSurface surface;
  std::vector<double> label, edgeDistance;
  bool edgeDistances = true;
  for (std::size_t s = 0; s < n; ++s) {
    const int value = a.labelValue + static_cast<int>(s);
    segments.push_back(segmentOf(value, names[s], s));
    const SegmentResult& result = outcome.structures[s].result;
    const TriangleSurface& own = result.surface;
    const int offset = static_cast<int>(surface.points.rows());
    surface.points.conservativeResize(offset + own.points.rows(), 3);
    surface.points.bottomRows(own.points.rows()) = own.points;
    surface.normals.conservativeResize(offset + own.normals.rows(), 3);
    surface.normals.bottomRows(own.normals.rows()) = own.normals;
    for (const std::array<int, 3>& t : own.triangles)
      surface.triangles.push_back({t[0] + offset, t[1] + offset, t[2] + offset});
    surface.triangleElement.insert(surface.triangleElement.end(), own.triangleElement.begin(),
                                   own.triangleElement.end());
    surface.triangleType.insert(surface.triangleType.end(), own.triangleType.begin(), own.triangleType.end());
    label.insert(label.end(), own.points.rows(), value);
    edgeDistances = edgeDistances && result.surfaceEdgeDistances.size() == own.points.rows();
    if (edgeDistances)
      edgeDistance.insert(edgeDistance.end(), result.surfaceEdgeDistances.data(),
                          result.surfaceEdgeDistances.data() + result.surfaceEdgeDistances.size());
  }
  std::vector<PointScalars> scalars = {{"label", Eigen::Map<const Eigen::VectorXd>(label.data(), label.size())}};
  if (edgeDistances)
    scalars.push_back(
        {kEdgeDistanceScalars, Eigen::Map<const Eigen::VectorXd>(edgeDistance.data(), edgeDistance.size())});
  const auto writeLabels = [&](const std::string& labelmap, const std::string& segmentation) {
    if (!labelmap.empty()) writeVolume(labels, labelmap, VoxelType::Label16);
    if (!segmentation.empty()) writeSlicerSegmentation(labels, segments, segmentation);
  };
  writeOutputs(a, writeLabels, surface, scalars, outcome.report);

  std::cout << std::fixed << std::setprecision(1) << "segmented " << n << " structures together in "
            << outcome.seconds << " s; voxels in two structures: " << outcome.sharedAlone << " alone, "
            << outcome.sharedTogether << " with the barrier, 0 in the labelmap\n";
  for (std::size_t s = 0; s < n; ++s) {
    const SegmentOutcome& one = outcome.structures[s];
    std::cout << "  " << segments[s].label << " " << segments[s].name << ": "
              << static_cast<double>(one.labelmap.count()) * image.geometry.spacing.prod() << " mm^3\n";
    reportWarnings(one, segments[s].name);
  }
}

void run(Arguments& a) {
  if (a.labelmap.empty() && a.model.empty() && a.segmentation.empty() && a.report.empty())
    throw UsageError("nothing to write: give --labelmap, --model, --segmentation and/or --report");
  if (!a.labelmap.empty()) requireExtension(a.labelmap, {".nrrd", ".nii", ".nii.gz", ".mha"}, "labelmap");
  if (!a.model.empty()) requireExtension(a.model, triangleSurfaceExtensions(), "model");
  if (!a.segmentation.empty() && !isSlicerSegmentationName(a.segmentation))
    throw UsageError(a.segmentation, "a 3D Slicer segmentation is written as .seg.nrrd");
  if (!a.report.empty()) requireExtension(a.report, {".json"}, "report");
  for (const std::string* path : {&a.labelmap, &a.model, &a.segmentation, &a.report}) {
    if (path->empty()) continue;
    requireWritableDirectoryFor(*path);
    for (const std::string& input : {a.image, a.landmarks}) requireNotInput(*path, input);
  }
  for (const auto& apply : a.afterParsing) apply(a);

  SlicerProgress progress(a.parameters.segment.simulation.maxLevel + 1);
  std::cout << "<filter-start><filter-name>DynSubSegment</filter-name></filter-start>" << std::endl;
  progress.stage(0.0, "reading the volume and the points");
  const Volume image = readVolume(a.image);
  const std::vector<LandmarkSource> files =
      a.landmarks.empty() ? std::vector<LandmarkSource>{} : landmarkSources({a.landmarks});
  // "Caudate_L;Putamen_L": two structures from the atlas.
  std::vector<std::string> atlasLabels;
  if (!a.atlasLabel.empty())
    for (const std::string& written : splitItems(a.atlasLabel, ';')) {  // "Caudate_L;" has an empty item
      const std::string label = trimmed(written);
      if (label.empty()) throw UsageError("--atlasLabel " + a.atlasLabel + ": an empty structure between ';'");
      atlasLabels.push_back(label);
    }
  const std::size_t structures = std::max(files.size(), atlasLabels.size());
  progress.setStructures(static_cast<int>(std::max<std::size_t>(structures, 1)));
  if (structures > 1) {
    runTogether(a, image, files, atlasLabels, progress);
  } else {
    if (!atlasLabels.empty()) a.atlasLabel = atlasLabels.front();
    runOne(a, image, files.empty() ? nullptr : &files.front(), progress);
  }
  progress.report(1.0);
  std::cout << "<filter-end><filter-name>DynSubSegment</filter-name></filter-end>" << std::endl;
}

}  // namespace

int main(int argc, char** argv) {
  dynsub::removeTemporariesOnInterrupt();
  Arguments arguments;
  const slicer::Module module = describe(arguments);
  // Slicer reads the descriptor from stdout, which must start with "<?xml".
  if (argc == 2 && std::strcmp(argv[1], "--xml") == 0) {
    std::cout << slicer::descriptor(module);
    return 0;
  }
  CLI::App app{module.title + ": " + module.description +
                   "\nA 3D Slicer CLI module: add this program's directory to Slicer's Additional module paths. "
                   "'--xml' prints its Execution Model descriptor.",
               "DynSubSegment"};
  slicer::addOptions(app, module);
  app.add_flag("--xml", "Print the Execution Model descriptor (alone)");
  try {
    std::vector<std::string> words = slicer::withJoinedPoints(module, argc, argv);
    std::reverse(words.begin(), words.end());  // CLI11 takes a vector last word first
    app.parse(words);
    if (app.count("--xml") > 0)
      throw dynsub::UsageError("--xml prints the module's descriptor and takes no other argument");
    run(arguments);
  } catch (const CLI::ParseError& error) {
    const int code = app.exit(error);
    if (code == 0) return 0;
    const std::string hint = dynsub::app::didYouMean(app, std::vector<std::string>(argv + 1, argv + argc));
    if (!hint.empty()) std::cerr << "DynSubSegment: " << hint << '\n';
    return 2;
  } catch (const dynsub::Error& error) {
    std::cerr << "DynSubSegment: error: " << inModuleTerms(dynsub::withoutTemporaryPrefix(error.what())) << '\n';
    return dynamic_cast<const dynsub::UsageError*>(&error) ? 2 : 1;
  } catch (const std::bad_alloc&) {
    std::cerr << "DynSubSegment: error: out of memory: the run needed more than this machine (or its limit) gives\n";
    return 1;
  } catch (const std::exception& error) {
    std::cerr << "DynSubSegment: unexpected error: " << error.what() << '\n';
    return 1;
  }
  return 0;
}
