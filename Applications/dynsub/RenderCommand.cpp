// dynsub render: the figures of segment and fit (Figures.h) from saved results.
#include <CLI/CLI.hpp>
#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <limits>
#include <memory>
#include <set>
#include <string>
#include <vector>

#include "Commands.h"
#include "FigureOutputs.h"
#include "dynsub/Error.h"
#include "dynsub/FigureInputs.h"
#include "dynsub/FileNames.h"
#include "dynsub/ImageIO.h"
#include "dynsub/Landmarks.h"
#include "dynsub/MeshIO.h"
#include "dynsub/OutputSet.h"
#include "dynsub/PointCloudIO.h"
#include "dynsub/Segmentation.h"
#include "dynsub/SurfacePolyData.h"

namespace dynsub::app {

namespace {

// The rows of `points` that are not rows of `drop`, compared exactly: fit
// writes its outliers with the digits that read back as the same doubles.
// Every copy of a dropped point goes: fit judges copies alike (they have the
// same neighbours), so it set them all aside. Warns when some of `drop` are
// not among `points` (outliers of another scan).
MatrixX3 withoutPoints(const MatrixX3& points, const MatrixX3& drop, const std::string& dropFile) {
  std::set<std::array<double, 3>> dropped;
  for (Eigen::Index r = 0; r < drop.rows(); ++r) dropped.insert({drop(r, 0), drop(r, 1), drop(r, 2)});
  std::set<std::array<double, 3>> found;
  std::vector<int> keep;
  for (Eigen::Index r = 0; r < points.rows(); ++r) {
    const std::array<double, 3> point{points(r, 0), points(r, 1), points(r, 2)};
    if (dropped.count(point)) {
      found.insert(point);
    } else {
      keep.push_back(static_cast<int>(r));
    }
  }
  if (found.size() < dropped.size())
    std::cerr << "warning: " << dropped.size() - found.size() << " of the " << dropped.size() << " points of "
              << dropFile << " are not points of --points\n";
  return points(keep, Eigen::all);
}

struct RenderCommandOptions {
  std::string surface, image, landmarks, points, outliers, convergence, controlMesh, out;
  FigureOptions figures;
};

// A median distance from the landmarks to the drawn surface's vertices
// (within a tessellation's spacing of the surface) beyond which they are
// named as not its own; with several lists, the nearest list's. A
// segmentation's landmarks lie on its boundary, within a voxel or two (the
// demo's caudate: a median 0.2 mm); mirrored across the midline, tens of mm
// away.
constexpr double kFarLandmarksMm = 5.0;

void runRender(const RenderCommandOptions& o) {
  requireFigureFormat(o.figures.format);
  std::string why;
  if (!figureDisplay(&why)) throw Error("rendering needs an X display: " + why);
  // Every input is read and checked before anything is written (the surface
  // file when the figures are drawn: a bad one leaves nothing behind).
  FigureInputs inputs;
  inputs.surfaceFile = o.surface;
  inputs.coordinates = o.figures.coordinates;
  std::unique_ptr<Volume> image;
  if (!o.image.empty()) {
    image = std::make_unique<Volume>(readVolume(o.image));
    inputs.image = image.get();
    inputs.imageFile = o.image;
  }
  if (!o.landmarks.empty()) {
    const std::vector<Landmark> landmarks = readLandmarks(o.landmarks);
    // Drawn on the image's slices, a landmark outside the image would be
    // left out of the figure without a word.
    try {
      if (image) requireLandmarksInside(image->geometry, landmarks);
    } catch (const LandmarkError& error) {
      throw Error(o.landmarks, std::string(error.what()) + " " + o.image + " (are the landmarks for another image?)");
    }
    inputs.landmarks = landmarkPositions(landmarks);
  }
  const auto readDrawnPoints = [](const std::string& path) {
    MatrixX3 points = readPointCloud(path).points;
    if (!points.allFinite()) throw Error(path, "a point is not a finite number");
    return points;
  };
  if (!o.points.empty()) inputs.dataPoints = readDrawnPoints(o.points);
  if (!o.outliers.empty()) {
    inputs.outliers = readDrawnPoints(o.outliers);
    if (!o.points.empty()) inputs.dataPoints = withoutPoints(inputs.dataPoints, inputs.outliers, o.outliers);
  }
  std::unique_ptr<ControlMesh> controlMesh;
  if (!o.controlMesh.empty()) {
    controlMesh = std::make_unique<ControlMesh>(readControlMesh(o.controlMesh));
    inputs.controlMesh = controlMesh.get();
  }
  ConvergenceHistory history;
  if (!o.convergence.empty()) {
    history = readConvergenceCsv(o.convergence);
    inputs.history = &history;
  }

  const std::filesystem::path dir(o.out);
  // render writes only figures: a run's other files, its convergence table
  // too, may be its inputs.
  for (const std::string& name : figureOutputNames()) {
    if (lowerCaseExtension(name) == ".csv") continue;
    for (const std::string& input :
         {o.surface, o.image, o.landmarks, o.points, o.outliers, o.convergence, o.controlMesh})
      requireNotInput((dir / name).string(), input);
  }
  prepareOutputDirectory(dir);
  OutputSet outputs(dir);
  writeFigures(inputs, o.figures.files(outputs, !o.convergence.empty()));
  outputs.commit();
  const std::string extension = "." + figureExtension(o.figures.format);
  std::cout << "wrote " << (dir / ("slices" + extension)).string() << ", surface3d" << extension
            << (o.convergence.empty() ? "" : ", convergence" + extension) << '\n';
  // Landmarks drawn far from the surface they outlined are another run's,
  // or read in the other convention; the figure alone would not say so. A
  // file of several structures' lists outlines this surface with one of them.
  if (!o.landmarks.empty()) {
    const MatrixX3 vertices = readSurfacePoints(o.surface);
    double nearestList = std::numeric_limits<double>::infinity();
    for (const LandmarkList& list : readLandmarkLists(o.landmarks)) {
      std::vector<double> nearest;
      for (const Landmark& landmark : list.landmarks)
        nearest.push_back((vertices.rowwise() - landmark.position.transpose()).rowwise().norm().minCoeff());
      if (nearest.empty()) continue;
      std::nth_element(nearest.begin(), nearest.begin() + nearest.size() / 2, nearest.end());
      nearestList = std::min(nearestList, nearest[nearest.size() / 2]);
    }
    if (std::isfinite(nearestList) && nearestList > kFarLandmarksMm)
      std::cerr << "warning: " << o.landmarks << ": the landmarks lie a median " << std::fixed << std::setprecision(1)
                << nearestList << " mm from the vertices of the surface " << o.surface
                << ": are they another image's or run's, or in the other convention (x and y negated)?\n";
  }
}

}  // namespace

void addRenderCommand(CLI::App& app) {
  auto o = std::make_shared<RenderCommandOptions>();
  CLI::App* command = app.add_subcommand(
      "render",
      "Make the figures of segment and fit from saved results: DIR/slices.png (slices through the surface with "
      "its contour and the landmarks), DIR/surface3d.png and, with --convergence, DIR/convergence.png (or .pdf "
      "or .svg: --figure-format).\n"
      "Needs an X display; without DISPLAY a private Xvfb is started for the run.");
  command->add_option("--surface", o->surface, "Limit surface: surface.vtp (or .obj, .ply, .stl), mm")->required();
  command->add_option("--image", o->image, "The image the surface was segmented in (slices show it)");
  command->add_option("--landmarks", o->landmarks, "Landmarks: .mrk.json, .fcsv or .csv");
  command->add_option("--points", o->points, "Range data the surface was fitted to");
  command->add_option("--outliers", o->outliers,
                      "Points fit set aside as outliers (its outliers.xyz): drawn in orange, and left out of --points");
  command->add_option("--control-mesh", o->controlMesh, "Control mesh to draw as a wireframe in the 3D figure");
  command->add_option("--convergence", o->convergence, "convergence.csv written by segment or fit");
  command->add_option("--out", o->out, "Output directory (created if missing; its parent must exist)")->required();
  o->figures.addStyleOptions(*command);
  command->callback([o] { runRender(*o); });
}

}  // namespace dynsub::app
