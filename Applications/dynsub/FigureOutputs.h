#pragma once
// What `segment` and `fit` add for people to look at: the convergence
// history (convergence.csv, always) and the figures of Figures.h
// (slices.png, surface3d.png, convergence.png, or PDF or SVG) when an X
// display is there.
#include <string>
#include <vector>

#include "dynsub/ConvergenceHistory.h"
#include "dynsub/FigureInputs.h"
#include "dynsub/Tessellation.h"

namespace CLI {
class App;
}

namespace dynsub {
class ControlMesh;
class OutputSet;
struct Volume;
}  // namespace dynsub

namespace dynsub::app {

struct FigureOptions {
  bool figures = true;
  FigureCoordinates coordinates = FigureCoordinates::Lps;
  FigureFormat format = FigureFormat::Png;
  double dpi = kDefaultFigureDpi;
  // --no-figures and addStyleOptions' options (segment, fit).
  void addOptions(CLI::App& command);
  // --figure-coordinates lps|ras, --figure-format png|pdf|svg, --figure-dpi
  // (segment, fit, render).
  void addStyleOptions(CLI::App& command);
  // When figures are wanted: the format's converter checked for (throws
  // without it), and their display made ready on a second thread
  // (Figures.h: prepareFigureDisplay) while the run goes on. Call it once the
  // inputs are read and checked, before the run's long part.
  void prepare() const;
  // The figures' files in `outputs` (slices.png, surface3d.png and, when
  // `convergence`, convergence.png, or .pdf or .svg), in this format and
  // resolution.
  FigureFiles files(OutputSet& outputs, bool convergence) const;
};

// Adds convergence.csv (of inputs.history, required) and, if wanted and
// possible, the three figures to `outputs`. Without a display it says so on
// stderr and writes no figure. (The figures an earlier run left in the
// directory that this one does not write are retired by the command:
// EarlierRuns.h.)
// `inputs` names the result's limit surface (outputSurface), and what else
// the figures show; without an image they draw `mesh` too. The figures'
// coordinates are the options'.
void addFigureOutputs(OutputSet& outputs, const FigureOptions& options, const ControlMesh& mesh, FigureInputs inputs);

// Every file addFigureOutputs may add: convergence.csv and each figure in
// each format.
std::vector<std::string> figureOutputNames();

}  // namespace dynsub::app
