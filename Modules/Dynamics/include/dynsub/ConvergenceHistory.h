#pragma once
// What a simulation did, step by step, for the convergence plot
// (ConvergencePlot.h) and for redrawing it later: the total energy of every
// step and, every few steps, a fit error (a dynsub fit: max_error_percent; a
// dynsub segment: the rms landmark distance in mm). Kept as CSV with the
// header `level,step,energy,fit_error` (fit_error empty where not measured).
// No VTK here: the commands record it without rendering.
#include <functional>
#include <limits>
#include <string>
#include <vector>

#include "dynsub/Simulation.h"

namespace dynsub {

struct ConvergenceSample {
  int level = 0;   // global refinements of the initial control mesh
  int step = 0;    // within the level, from 1
  double energy = 0;  // N mm
  double fitError = std::numeric_limits<double>::quiet_NaN();  // NaN: not measured at this step
};

struct ConvergenceHistory {
  std::string fitErrorName;  // axis title, with its unit
  std::vector<ConvergenceSample> samples;

  // Adds a step. A step number not after the level's last one means the level
  // restarted (a smaller time step after divergence): its earlier samples go.
  void add(const ConvergenceSample& sample);
  // Puts `fitError` on the level's last step: the measure a command takes
  // where the level ended, so that the chart ends where the report does. No
  // sample of the level: nothing.
  void setLevelEndError(int level, double fitError);
};

// Records every step's energy and, every `stride` steps (and at each level's
// first), a fit error measured on the current surface.
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

// The CSV's first line is "# fit_error: <fitErrorName>". Both throw
// dynsub::Error naming the file (a malformed line gives its number).
void writeConvergenceCsv(const ConvergenceHistory& history, const std::string& path);
ConvergenceHistory readConvergenceCsv(const std::string& path);

}  // namespace dynsub
