#include "FigureOutputs.h"

#include <CLI/CLI.hpp>
#include <iostream>
#include <map>
#include <string>
#include <vector>

#include "CommandLine.h"
#include "dynsub/Error.h"
#include "dynsub/FigureInputs.h"
#include "dynsub/OutputSet.h"

namespace dynsub::app {

namespace {

const std::map<std::string, FigureFormat>& formatNames() {
  static const std::map<std::string, FigureFormat> names{
      {"png", FigureFormat::Png}, {"pdf", FigureFormat::Pdf}, {"svg", FigureFormat::Svg}};
  return names;
}

const char* const kFigureNames[] = {"slices", "surface3d", "convergence"};
const char* const kConvergenceTable = "convergence.csv";

}  // namespace

void FigureOptions::addOptions(CLI::App& command) {
  command.add_flag("!--no-figures", figures,
                   "Do not render the figures slices, surface3d and convergence (rendering needs an X display; "
                   "without DISPLAY a private Xvfb is started for the run)");
  addStyleOptions(command);
}

void FigureOptions::addStyleOptions(CLI::App& command) {
  const std::map<std::string, FigureCoordinates> coordinateNames{{"lps", FigureCoordinates::Lps},
                                                                 {"ras", FigureCoordinates::Ras}};
  command
      .add_option("--figure-coordinates", coordinates,
                  "The coordinates the slices figure prints and names: lps (x to the left, y posterior; DICOM, "
                  "ITK, 3D Slicer's files, this tool's outputs) or ras (x to the right, y anterior; NIfTI, "
                  "FreeSurfer, MNI)")
      ->transform(CLI::CheckedTransformer(coordinateNames, CLI::ignore_case))
      ->default_str("lps");
  command
      .add_option("--figure-format", format,
                  "The figures' file format: png, or pdf or svg for papers and posters (text as vector outlines, "
                  "the image and the surface as a raster at --figure-dpi; made with pdftocairo, Debian's "
                  "poppler-utils)")
      ->transform(CLI::CheckedTransformer(formatNames(), CLI::ignore_case))
      ->default_str("png");
  command
      .add_option("--figure-dpi", dpi,
                  "Pixels per inch of the figures at their nominal size (slices 12 x 8 in, 3D view 8 x 8 in, "
                  "convergence 9 x 5 in); text, lines and dots grow with it. 100 gives 1200 x 800 pixels of slices, "
                  "300 a print-quality 3600 x 2400")
      ->check(numberBetween(kMinFigureDpi, kMaxFigureDpi, false))
      ->default_str("100");
}

void FigureOptions::prepare() const {
  if (!figures) return;
  requireFigureFormat(format);
  prepareFigureDisplay();
}

FigureFiles FigureOptions::files(OutputSet& outputs, bool convergence) const {
  const std::string extension = "." + figureExtension(format);
  FigureFiles files;
  files.slices = outputs.add("slices" + extension);
  files.surface3d = outputs.add("surface3d" + extension);
  if (convergence) files.convergence = outputs.add("convergence" + extension);
  files.format = format;
  files.dpi = dpi;
  return files;
}

void addFigureOutputs(OutputSet& outputs, const FigureOptions& options, const ControlMesh& mesh, FigureInputs inputs) {
  if (!inputs.history) throw Error("internal: a result's figures need its convergence history");
  writeConvergenceCsv(*inputs.history, outputs.add(kConvergenceTable));
  std::string why;
  const bool drawn = options.figures && figureDisplay(&why);
  if (options.figures && !drawn) std::cerr << "warning: no figures written: " << why << '\n';
  if (!drawn) return;
  // Without an image the control mesh shows what the surface is made of.
  if (!inputs.image) inputs.controlMesh = &mesh;
  inputs.coordinates = options.coordinates;
  writeFigures(inputs, options.files(outputs, true));
}

std::vector<std::string> figureOutputNames() {
  std::vector<std::string> names{kConvergenceTable};
  for (const auto& [extension, format] : formatNames())
    for (const char* name : kFigureNames) names.push_back(std::string(name) + "." + extension);
  return names;
}

}  // namespace dynsub::app
