#include "FigureOutputs.h"

#include <iostream>

#include <CLI/CLI.hpp>

#include "dynsub/Error.h"
#include "dynsub/FigureInputs.h"
#include "dynsub/OutputSet.h"

namespace dynsub::app {

void FigureOptions::addOptions(CLI::App& command) {
  command.add_flag("!--no-figures", figures,
                   "Do not render slices.png, surface3d.png and convergence.png (rendering needs an X display; "
                   "without DISPLAY a private Xvfb is started for the run)");
}

void FigureOptions::prepare() const {
  if (!figures) return;
  prepareFigureDisplay();
}

void addFigureOutputs(OutputSet& outputs, const FigureOptions& options, const ControlMesh& mesh,
                      const TriangleSurface& surface, const ConvergenceHistory& history, const Volume* image,
                      const MatrixX3& landmarks, const MatrixX3& dataPoints, const Eigen::VectorXd& edgeDistances) {
  writeConvergenceCsv(history, outputs.add("convergence.csv"));
  if (!options.figures) return;
  std::string why;
  if (!figureDisplay(&why)) {
    std::cerr << "warning: no figures written: " << why << '\n';
    return;
  }
  FigureInputs inputs;
  inputs.surface = &surface;
  inputs.image = image;
  // Without an image the control mesh shows what the surface is made of.
  if (!image) inputs.controlMesh = &mesh;
  inputs.landmarks = landmarks;
  inputs.dataPoints = dataPoints;
  inputs.history = &history;
  inputs.edgeDistances = edgeDistances;
  FigureFiles files;
  files.slices = outputs.add("slices.png");
  files.surface3d = outputs.add("surface3d.png");
  files.convergence = outputs.add("convergence.png");
  writeFigures(inputs, files);
}

}  // namespace dynsub::app
