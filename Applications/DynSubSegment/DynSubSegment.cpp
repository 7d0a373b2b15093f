// DynSubSegment: `dynsub segment` as a 3D Slicer CLI module (Slicer
// Execution Model). Slicer runs `DynSubSegment --xml` to build the module's
// panel, then runs it with the data as files (the volume as .nrrd, the
// result as the label image and .vtp model it asks for) and each markups
// point as one `--seed x,y,z` in LPS mm. Progress goes to stdout as
// <filter-progress> tags, which Slicer shows as the module's progress bar.
//
// Exit codes: 0 success; 1 an error in the inputs or the run (stderr names the
// file and the problem, and nothing is written); 2 a usage error.
#include <cmath>
#include <cstring>
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <memory>
#include <sstream>

#include <CLI/CLI.hpp>

#include "ExecutionModel.h"
#include "SegmentRun.h"
#include "dynsub/AtomicOutput.h"
#include "dynsub/Error.h"
#include "dynsub/FileNames.h"
#include "dynsub/ImageIO.h"
#include "dynsub/SurfaceWriter.h"

namespace {

using namespace dynsub;
using dynsub::slicer::Parameter;

struct Arguments {
  std::string image, landmarks, inside, labelmap, model, report;
  std::vector<std::string> seeds;
  int labelValue = 1;
  bool pointsReachEnds = false;
  std::string potential = "edges";
  SegmentOptions segment;
  SeedOptions seed;
};

slicer::Module describe(Arguments& a) {
  slicer::Module m;
  m.category = "Segmentation";
  m.title = "DynSub Segment";
  m.description =
      "Segments a structure with a dynamic Catmull-Clark subdivision surface: a smooth closed surface, defined by "
      "a small control mesh, moves toward the image's edges and toward points placed on the structure's boundary, "
      "and is refined until it meets them. Give at least 4 boundary points, or one point inside the structure "
      "(its tissue is grown from there and the surface starts on that region's boundary).";
  m.version = DYNSUB_VERSION;
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
                           "added to the points above.",
                           &a.landmarks, "input", "", "", "", {}, -1});
  io.parameters.push_back({"point", "coordinateSystem=\"lps\"", "inside", "inside", "Point inside",
                           "One click inside the structure: the surface starts from the region of like tissue "
                           "grown from it. Without boundary points that region's boundary guides the surface.",
                           &a.inside, "", "", "", "", {}, -1});
  io.parameters.push_back({"image", "type=\"label\" reference=\"inputVolume\"", "outputLabelmap", "labelmap",
                           "Output labelmap", "The structure as a label image on the input volume's grid.",
                           &a.labelmap, "output", "", "", "", {}, -1});
  io.parameters.push_back({"geometry", "type=\"model\"", "outputModel", "model", "Output model",
                           "The fitted limit surface as a triangle model (LPS mm).", &a.model, "output", "", "", "",
                           {}, -1});
  io.parameters.push_back({"file", "fileExtensions=\".json\"", "report", "report", "Report",
                           "Optional: the run's numbers and warnings as JSON (the report.json of dynsub segment).",
                           &a.report, "output", "", "", "", {}, -1});
  io.parameters.push_back({"integer", "", "labelValue", "labelValue", "Label value",
                           "The structure's value in the output labelmap (Slicer colours it by this value).",
                           &a.labelValue, "", "1", "255", "1", {}, -1});

  slicer::ParameterGroup model{"Surface", "How the surface moves and when it is refined.", false, {}};
  model.parameters.push_back({"string-enumeration", "", "potential", "potential", "Edges",
                              "edges: distance to edges found by a 3D Monga-Deriche detector; gradient: the "
                              "smoothed gradient magnitude.",
                              &a.potential, "", "", "", "", {"edges", "gradient"}, -1});
  model.parameters.push_back({"double", "", "sigma", "sigma", "Edge smoothing (mm)",
                              "Gaussian smoothing of the edge detector.", &a.segment.edges.sigma, "", "0.2", "5",
                              "0.1", {}, -1});
  model.parameters.push_back({"double", "", "captureRange", "captureRange", "Capture range (mm)",
                              "How far from an edge the image still pulls the surface.",
                              &a.segment.edges.captureRange, "", "1", "30", "0.5", {}, -1});
  model.parameters.push_back({"double", "", "imageForce", "imageForce", "Image force (N/mm^2)",
                              "Strength of the pull toward edges per unit of surface.", &a.segment.imageForce, "",
                              "0", "10", "0.01", {}, -1});
  model.parameters.push_back({"double", "", "landmarkStiffness", "landmarkStiffness", "Point stiffness (N/mm)",
                              "Spring stiffness of each boundary point.", &a.segment.landmarkStiffness, "", "0",
                              "1000", "0.5", {}, -1});
  model.parameters.push_back({"double", "", "landmarkTolerance", "landmarkTolerance", "Point tolerance (mm)",
                              "The surface is refined while a boundary point is farther than this from it.",
                              &a.segment.landmarkTolerance, "", "0.05", "10", "0.05", {}, -1});
  model.parameters.push_back({"double", "", "inflation", "inflation", "Inflation (N/mm^2)",
                              "Pressure along the normal: positive grows the surface, negative shrinks it.",
                              &a.segment.inflation, "", "-1", "1", "0.01", {}, -1});
  model.parameters.push_back({"double", "", "margin", "margin", "Margin (mm)",
                              "The region of interest around the initial model and the points.", &a.segment.margin,
                              "", "1", "100", "1", {}, -1});
  model.parameters.push_back({"boolean", "", "pointsReachEnds", "pointsReachEnds", "Points reach both ends",
                              "Check when the boundary points include the structure's first and last slices. "
                              "Unchecked, the surface is carried past the outermost slices with points to where "
                              "the structure's tissue ends, since experts seldom place points there; when the "
                              "points already reach the ends, that can carry it on into like tissue.",
                              &a.pointsReachEnds, "", "", "", "", {}, -1});
  model.parameters.push_back({"integer", "", "maxLevel", "maxLevel", "Refinements",
                              "Global refinements of the control mesh allowed.", &a.segment.simulation.maxLevel, "",
                              "0", "6", "1", {}, -1});

  slicer::ParameterGroup seed{"Point inside", "How the region is grown from a point inside the structure.", true, {}};
  seed.parameters.push_back({"double", "", "seedWindow", "seedWindow", "Intensity window (spreads)",
                             "The intensities grown through: this many robust spreads either side of the median "
                             "near the click.",
                             &a.seed.window, "", "0.5", "20", "0.5", {}, -1});
  seed.parameters.push_back({"double", "", "seedOpening", "seedOpening", "Opening (mm)",
                             "Radius of the opening that cuts thin bridges to like tissue nearby.", &a.seed.opening,
                             "", "0", "10", "0.5", {}, -1});
  seed.parameters.push_back({"double", "", "seedReach", "seedReach", "Reach (mm)",
                             "How far from the click the region may grow.", &a.seed.reach, "", "5", "200", "5", {},
                             -1});
  m.groups = {io, model, seed};
  return m;
}

// "x,y,z" as Slicer writes a point: three finite numbers.
Vector3 parsePoint(const std::string& text, const std::string& flag) {
  std::stringstream in(text);
  Vector3 p;
  char comma1 = 0, comma2 = 0;
  if (!(in >> p.x() >> comma1 >> p.y() >> comma2 >> p.z()) || comma1 != ',' || comma2 != ',' || !p.allFinite() ||
      (in >> std::ws, !in.eof()))
    throw Error("--" + flag + " " + text + ": expected x,y,z (three finite numbers, LPS mm)");
  return p;
}

// Slicer's progress bar: <filter-progress> from 0 to 1, each level of the
// evolution an equal share (a level's steps approach its end).
class SlicerProgress {
 public:
  explicit SlicerProgress(int levels) : levels_(levels) {}
  void stage(double fraction, const std::string& comment) {
    std::cout << "<filter-comment>" << comment << "</filter-comment>\n";
    report(fraction);
  }
  ProgressCallback callback() {
    return [this](const Progress& p) {
      const double withinLevel = 1.0 - 1.0 / (1.0 + p.step / 50.0);
      report(0.1 + 0.8 * (std::min(p.level, levels_ - 1) + withinLevel) / levels_);
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
  double last_ = -1;
};

void requireExtension(const std::string& path, const std::vector<std::string>& known, const std::string& what) {
  const std::string extension = lowerCaseExtension(path);
  for (const std::string& k : known)
    if (extension == k) return;
  std::string list;
  for (const std::string& k : known) list += (list.empty() ? "" : ", ") + k;
  throw Error(path, "unknown " + what + " format '" + extension + "' (expected " + list + ")");
}

void run(Arguments a) {
  if (a.labelmap.empty() && a.model.empty() && a.report.empty())
    throw Error("nothing to write: give --labelmap, --model and/or --report");
  if (!a.labelmap.empty()) requireExtension(a.labelmap, {".nrrd", ".nii", ".gz", ".mha"}, "labelmap");
  if (!a.model.empty()) requireExtension(a.model, triangleSurfaceExtensions(), "model");
  if (!a.report.empty()) requireExtension(a.report, {".json"}, "report");
  for (const std::string* path : {&a.labelmap, &a.model, &a.report})
    if (!path->empty()) requireWritableDirectoryFor(*path);
  if (a.potential == "gradient") a.segment.edges.method = EdgeMethod::GradientMagnitude;
  a.segment.sliceEnds.enabled = !a.pointsReachEnds;
  checkSegmentOptions(a.segment);

  SlicerProgress progress(a.segment.simulation.maxLevel + 1);
  std::cout << "<filter-start><filter-name>DynSubSegment</filter-name></filter-start>" << std::endl;
  progress.stage(0.0, "reading the volume and the points");
  app::SegmentInputs in;
  in.image = a.image;
  const Volume image = readVolume(a.image);
  for (std::size_t i = 0; i < a.seeds.size(); ++i)
    in.landmarks.push_back({"seed-" + std::to_string(i + 1), parsePoint(a.seeds[i], "seed")});
  in.landmarkSource = "--seed";
  if (!a.landmarks.empty()) {
    const std::vector<Landmark> fromFile = readLandmarks(a.landmarks);
    in.landmarks.insert(in.landmarks.end(), fromFile.begin(), fromFile.end());
    in.landmarkSource = a.seeds.empty() ? a.landmarks : "--seed and " + a.landmarks;
  }
  if (!a.inside.empty()) {
    in.init.kind = app::InitialModel::Kind::Seed;
    in.init.center = parsePoint(a.inside, "inside");
    in.init.text = "inside:" + a.inside;
  } else if (in.landmarks.size() == 1) {
    // One point cannot outline a structure: it is read as a click inside it.
    in.init.kind = app::InitialModel::Kind::Seed;
    in.init.center = in.landmarks.front().position;
    in.init.text = "inside:" + (a.seeds.empty() ? std::string("the one point of ") + a.landmarks : a.seeds.front());
    in.landmarks.clear();
  } else if (in.landmarks.size() < 4) {
    throw Error(in.landmarks.empty() ? std::string("no points: give at least 4 boundary points (--seed x,y,z "
                                                   "each) or one point inside the structure (--inside x,y,z)")
                                     : in.landmarkSource + ": " + std::to_string(in.landmarks.size()) +
                                           " boundary points are too few to outline a structure: give at least 4, "
                                           "or one point inside it (--inside x,y,z)");
  } else {
    in.init.text = "auto";
  }
  in.segment = a.segment;
  in.seed = a.seed;
  in.potential = a.potential;

  progress.stage(0.05, "evolving the surface");
  const app::SegmentRun run = app::runSegmentation(image, in, progress.callback());
  progress.stage(0.95, "writing the results");

  // All outputs appear together or none does.
  std::vector<std::unique_ptr<AtomicOutput>> outputs;
  if (!a.labelmap.empty()) {
    outputs.push_back(std::make_unique<AtomicOutput>(a.labelmap));
    writeMask(run.labelmap, outputs.back()->temporaryPath(), static_cast<std::uint8_t>(a.labelValue));
  }
  if (!a.model.empty()) {
    std::vector<PointScalars> scalars;
    if (run.result.surfaceEdgeDistances.size()) scalars.push_back({"edge_distance_mm", run.result.surfaceEdgeDistances});
    outputs.push_back(std::make_unique<AtomicOutput>(a.model));
    writeTriangleSurface(run.result.surface, outputs.back()->temporaryPath(), scalars, "LPS");
  }
  if (!a.report.empty()) {
    outputs.push_back(std::make_unique<AtomicOutput>(a.report));
    run.report.write(outputs.back()->temporaryPath());
  }
  for (auto& output : outputs) output->commit();

  const double volume = run.labelmap.count() * image.geometry.spacing.prod();
  std::cout << std::fixed << std::setprecision(1) << "segmented " << volume << " mm^3 with "
            << run.result.mesh.vertexCount() << " control vertices in " << run.seconds << " s\n";
  const std::string carried = app::carriedPastSlices(run.result);
  if (!carried.empty())
    std::cout << "<filter-comment>followed the structure's tissue past the outermost slices with points and "
                 "pulled the surface there: "
              << carried << " (check Points reach both ends if your points already reach them)</filter-comment>\n";
  for (const std::string& warning : run.warnings) std::cerr << "warning: " << warning << '\n';
  progress.report(1.0);
  std::cout << "<filter-end><filter-name>DynSubSegment</filter-name></filter-end>" << std::endl;
}

}  // namespace

int main(int argc, char** argv) {
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
    app.parse(argc, argv);
    run(arguments);
  } catch (const CLI::ParseError& error) {
    const int code = app.exit(error);
    return code == 0 ? 0 : 2;
  } catch (const dynsub::Error& error) {
    std::cerr << "DynSubSegment: error: " << dynsub::withoutTemporaryPrefix(error.what()) << '\n';
    return 1;
  } catch (const std::exception& error) {
    std::cerr << "DynSubSegment: unexpected error: " << error.what() << '\n';
    return 1;
  }
  return 0;
}
