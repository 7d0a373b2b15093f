#pragma once
// What `segment` and `fit` add for people to look at: the convergence
// history (convergence.csv, always) and the figures of Figures.h
// (slices.png, surface3d.png, convergence.png) when an X display is there.
#include <functional>
#include <string>

#include "dynsub/ConvergenceHistory.h"
#include "dynsub/Simulation.h"

namespace CLI {
class App;
}

namespace dynsub {
struct Volume;
}

namespace dynsub::app {

class OutputSet;

// Records every step's energy and, every `stride` steps, a fit error measured
// on the current surface.
class ConvergenceRecorder {
 public:
  using FitError = std::function<double(const Progress& progress)>;
  ConvergenceRecorder(std::string fitErrorName, FitError fitError, int stride);
  // Records, then calls `next` (may be empty).
  ProgressCallback callback(ProgressCallback next);
  const ConvergenceHistory& history() const { return history_; }

 private:
  ConvergenceHistory history_;
  FitError fitError_;
  int stride_;
};

struct FigureOptions {
  bool figures = true;
  void addOptions(CLI::App& command);
};

// Adds convergence.csv and, if wanted and possible, the three figures to
// `outputs`. Without a display it says so on stderr and writes no figure.
// `image` may be null; landmarks and dataPoints are #points x 3 (mm), possibly empty.
void addFigureOutputs(OutputSet& outputs, const FigureOptions& options, const ControlMesh& mesh,
                      const ConvergenceHistory& history, const Volume* image, const Matrix3X& landmarks,
                      const Matrix3X& dataPoints);

}  // namespace dynsub::app
