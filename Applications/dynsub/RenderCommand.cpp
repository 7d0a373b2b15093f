// dynsub render: the figures of segment and fit (Figures.h) from saved results.
#include <filesystem>
#include <iostream>
#include <memory>

#include <CLI/CLI.hpp>
#include <vtkPolyData.h>
#include <vtkRenderWindow.h>

#include "Commands.h"
#include "Reporting.h"
#include "dynsub/Error.h"
#include "dynsub/Figures.h"
#include "dynsub/ImageIO.h"
#include "dynsub/Landmarks.h"
#include "dynsub/MeshIO.h"
#include "dynsub/PointCloudIO.h"
#include "dynsub/SlicePlanes.h"
#include "dynsub/SurfacePolyData.h"
#include "dynsub/SurfaceView.h"

namespace dynsub::app {

namespace {

struct RenderCommandOptions {
  std::string surface, image, landmarks, points, convergence, controlMesh, out;
};

void runRender(const RenderCommandOptions& o) {
  std::string why;
  if (!figureDisplay(&why)) throw Error("rendering needs an X display: " + why);
  // Every input is read and checked before anything is written.
  const vtkSmartPointer<vtkPolyData> surface = readSurfacePolyData(o.surface);
  FigureScene scene;
  scene.surface = surface;
  std::unique_ptr<ImageSlices> image;
  if (!o.image.empty()) {
    image = std::make_unique<ImageSlices>(readVolume(o.image));
    scene.image = image.get();
  }
  if (!o.landmarks.empty()) scene.landmarks = landmarkPositions(readLandmarks(o.landmarks));
  if (!o.points.empty()) scene.dataPoints = readPointCloud(o.points);
  vtkSmartPointer<vtkPolyData> wireframe;
  if (!o.controlMesh.empty()) {
    wireframe = controlMeshWireframe(readControlMesh(o.controlMesh));
    scene.controlMesh = wireframe;
  }
  ConvergenceHistory history;
  if (!o.convergence.empty()) history = readConvergenceCsv(o.convergence);

  const std::filesystem::path dir(o.out);
  prepareOutputDirectory(dir);
  OutputSet outputs(dir);
  writePng(slicesFigure(scene), outputs.add("slices.png"));
  writePng(surfaceFigure(scene), outputs.add("surface3d.png"));
  if (!o.convergence.empty()) writePng(convergenceFigure(history), outputs.add("convergence.png"));
  outputs.commit();
  std::cout << "wrote " << (dir / "slices.png").string() << ", surface3d.png"
            << (o.convergence.empty() ? "" : ", convergence.png") << '\n';
}

}  // namespace

void addRenderCommand(CLI::App& app) {
  auto o = std::make_shared<RenderCommandOptions>();
  CLI::App* command = app.add_subcommand(
      "render",
      "Make the figures of segment and fit from saved results: DIR/slices.png (slices through the surface with "
      "its contour and the landmarks), DIR/surface3d.png and, with --convergence, DIR/convergence.png.\n"
      "Needs an X display; without DISPLAY a private Xvfb is started for the run.");
  command->add_option("--surface", o->surface, "Limit surface: surface.vtp (or .obj, .ply, .stl), mm")->required();
  command->add_option("--image", o->image, "The image the surface was segmented in (slices show it)");
  command->add_option("--landmarks", o->landmarks, "Landmarks: .mrk.json, .fcsv or .csv");
  command->add_option("--points", o->points, "Range data the surface was fitted to");
  command->add_option("--control-mesh", o->controlMesh, "Control mesh to draw as a wireframe in the 3D figure");
  command->add_option("--convergence", o->convergence, "convergence.csv written by segment or fit");
  command->add_option("--out", o->out, "Output directory (created if missing; its parent must exist)")->required();
  command->callback([o] { runRender(*o); });
}

}  // namespace dynsub::app
