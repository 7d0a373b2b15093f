#include "FigureOutputs.h"

#include <iostream>
#include <map>
#include <string>

#include <CLI/CLI.hpp>

#include "dynsub/Error.h"
#include "dynsub/FigureInputs.h"
#include "dynsub/OutputSet.h"

namespace dynsub::app {

void addFigureCoordinatesOption(CLI::App& command, FigureCoordinates& coordinates) {
  const std::map<std::string, FigureCoordinates> names{{"lps", FigureCoordinates::Lps},
                                                       {"ras", FigureCoordinates::Ras}};
  command
      .add_option("--figure-coordinates", coordinates,
                  "The coordinates the slices figure prints and names: lps (x to the left, y posterior; DICOM, "
                  "ITK, 3D Slicer's files, this tool's outputs) or ras (x to the right, y anterior; NIfTI, "
                  "FreeSurfer, MNI)")
      ->transform(CLI::CheckedTransformer(names, CLI::ignore_case))
      ->default_str("lps");
}

void FigureOptions::addOptions(CLI::App& command) {
  command.add_flag("!--no-figures", figures,
                   "Do not render slices.png, surface3d.png and convergence.png (rendering needs an X display; "
                   "without DISPLAY a private Xvfb is started for the run)");
  addFigureCoordinatesOption(command, coordinates);
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
  inputs.coordinates = options.coordinates;
  FigureFiles files;
  files.slices = outputs.add("slices.png");
  files.surface3d = outputs.add("surface3d.png");
  files.convergence = outputs.add("convergence.png");
  writeFigures(inputs, files);
}

}  // namespace dynsub::app
