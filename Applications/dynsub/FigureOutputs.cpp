#include "FigureOutputs.h"

#include <cmath>
#include <iostream>
#include <memory>

#include <CLI/CLI.hpp>
#include <vtkPolyData.h>
#include <vtkRenderWindow.h>

#include "Reporting.h"
#include "dynsub/Figures.h"
#include "dynsub/LimitSurface.h"
#include "dynsub/SlicePlanes.h"
#include "dynsub/SurfacePolyData.h"
#include "dynsub/SurfaceView.h"
#include "dynsub/Tessellation.h"

namespace dynsub::app {

ConvergenceRecorder::ConvergenceRecorder(std::string fitErrorName, FitError fitError, int stride)
    : fitError_(std::move(fitError)), stride_(stride) {
  history_.fitErrorName = std::move(fitErrorName);
}

ProgressCallback ConvergenceRecorder::callback(ProgressCallback next) {
  return [this, next](const Progress& p) {
    ConvergenceSample sample{p.level, p.step, p.energy, std::nan("")};
    if (fitError_ && p.surface && p.controlPoints && (p.step == 1 || p.step % stride_ == 0))
      sample.fitError = fitError_(p);
    history_.add(sample);
    if (next) next(p);
  };
}

void FigureOptions::addOptions(CLI::App& command) {
  command.add_flag("!--no-figures", figures,
                   "Do not render slices.png, surface3d.png and convergence.png (rendering needs an X display; "
                   "without DISPLAY a private Xvfb is started for the run)");
}

void addFigureOutputs(OutputSet& outputs, const FigureOptions& options, const ControlMesh& mesh,
                      const ConvergenceHistory& history, const Volume* image, const Matrix3X& landmarks,
                      const Matrix3X& dataPoints) {
  writeConvergenceCsv(history, outputs.add("convergence.csv"));
  if (!options.figures) return;
  std::string why;
  if (!figureDisplay(&why)) {
    std::cerr << "warning: no figures written: " << why << '\n';
    return;
  }
  const vtkSmartPointer<vtkPolyData> surface = toPolyData(tessellate(LimitSurface(mesh), mesh.points(), 8));
  std::unique_ptr<ImageSlices> slices;
  vtkSmartPointer<vtkPolyData> wireframe;
  FigureScene scene;
  scene.surface = surface;
  scene.landmarks = landmarks;
  scene.dataPoints = dataPoints;
  if (image) {
    slices = std::make_unique<ImageSlices>(*image);
    scene.image = slices.get();
  }
  writePng(slicesFigure(scene), outputs.add("slices.png"));
  // Without an image the control mesh shows what the surface is made of.
  if (!image) {
    wireframe = controlMeshWireframe(mesh);
    scene.controlMesh = wireframe;
  }
  writePng(surfaceFigure(scene), outputs.add("surface3d.png"));
  writePng(convergenceFigure(history), outputs.add("convergence.png"));
}

}  // namespace dynsub::app
