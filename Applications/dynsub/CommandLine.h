#pragma once
// What the commands that run a simulation share on the command line: the
// physics and solver options, and a progress line on a terminal.
#include <limits>
#include <string>
#include <vector>

#include "dynsub/SegmentParameters.h"
#include "dynsub/Simulation.h"

namespace CLI {
class App;
class Validator;
}

namespace dynsub::app {

// Command-line options for SimulationOptions (material, integrator, levels).
struct SimulationArguments {
  std::string scheme, solver;
  SimulationOptions values;
  void addOptions(CLI::App& command, const SimulationOptions& defaults);
  // `base` with the options given on the command line; throws dynsub::Error on bad values.
  SimulationOptions apply(SimulationOptions base) const;
};

// One option per row of the segmentation parameters' table
// (SegmentParameters.h), under its group's heading, with its range as a check
// and the value in `parameters` now as its default; `parameters` must outlive
// the parsing.
void addSegmentParameterOptions(CLI::App& command, SegmentParameters& parameters);

// Checks for a number on the command line, each refusal saying what is
// wrong: "--samples-per-face: 'abc' is not a number", "'2.5' is not a whole
// number", "'2000' is not between 1 and 1024", "'-1' is not a finite number > 0".
// A whole number is taken in decimal digits only.
CLI::Validator numberBetween(double low, double high, bool whole);
// Finite, > 0 (or >= 0) and at most `largest`.
CLI::Validator positiveNumber(double largest = std::numeric_limits<double>::infinity());
CLI::Validator nonNegativeNumber(double largest = std::numeric_limits<double>::infinity());

// For a usage error: "did you mean 'segment'?" for a command that is not one
// of `app`'s subcommands, or "did you mean '--landmarks'?" for a long option
// the command does not have, when a known one is near; empty otherwise.
// `words` are the program's arguments without its name.
std::string didYouMean(const CLI::App& app, const std::vector<std::string>& words);

// "\rlevel L  step S  energy E" on stderr while stderr is a terminal; silent otherwise.
class ProgressLine {
 public:
  ProgressLine();
  ProgressCallback callback();
  void finish();

 private:
  bool terminal_;
  bool written_ = false;
};

}  // namespace dynsub::app
