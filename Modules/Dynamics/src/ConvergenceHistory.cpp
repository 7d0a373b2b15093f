#include "dynsub/ConvergenceHistory.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <iomanip>
#include <sstream>

#include "dynsub/AtomicOutput.h"
#include "dynsub/Error.h"
#include "dynsub/TextFields.h"

namespace dynsub {

namespace {
const char* const kNamePrefix = "# fit_error: ";
const char* const kHeader = "level,step,energy,fit_error";
}  // namespace

void ConvergenceHistory::add(const ConvergenceSample& sample) {
  while (!samples.empty() && samples.back().level == sample.level && samples.back().step >= sample.step)
    samples.pop_back();
  samples.push_back(sample);
}

void ConvergenceHistory::setLevelEndError(int level, double fitError) {
  const auto last = std::find_if(samples.rbegin(), samples.rend(),
                                 [level](const ConvergenceSample& s) { return s.level == level; });
  if (last != samples.rend()) last->fitError = fitError;
}

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

void writeConvergenceCsv(const ConvergenceHistory& history, const std::string& path) {
  AtomicOutput output(path);
  {
    std::ofstream out(output.temporaryPath());
    if (!out) throw Error(path, "cannot write the file");
    out << kNamePrefix << history.fitErrorName << '\n' << kHeader << '\n' << std::setprecision(10);
    for (const ConvergenceSample& s : history.samples) {
      out << s.level << ',' << s.step << ',' << s.energy << ',';
      if (std::isfinite(s.fitError)) out << s.fitError;
      out << '\n';
    }
    if (!out) throw Error(path, "writing the file failed");
  }
  output.commit();
}

ConvergenceHistory readConvergenceCsv(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw Error(path, "cannot open the file");
  ConvergenceHistory history;
  std::string line;
  int number = 0;
  bool header = false;
  while (std::getline(in, line)) {
    ++number;
    if (line.rfind(kNamePrefix, 0) == 0) {
      history.fitErrorName = line.substr(std::string(kNamePrefix).size());
      continue;
    }
    if (!header) {
      if (line != kHeader) throw Error(path, "line " + std::to_string(number) + ": expected the header " + kHeader);
      header = true;
      continue;
    }
    std::stringstream fields(line);
    std::string level, step, energy, fit;
    std::getline(fields, level, ',');
    std::getline(fields, step, ',');
    std::getline(fields, energy, ',');
    std::getline(fields, fit, ',');
    ConvergenceSample s;
    // Level and step: whole numbers a level or a step count can be.
    auto whole = [](const std::string& field, int& out) {
      double value = 0;
      if (!parseNumber(field, value) || value != std::floor(value) || std::abs(value) > 1e9) return false;
      out = static_cast<int>(value);
      return true;
    };
    if (!whole(level, s.level) || !whole(step, s.step) || !parseNumber(energy, s.energy) ||
        (!fit.empty() && !parseNumber(fit, s.fitError)))
      throw Error(path, "line " + std::to_string(number) + ": expected level,step,energy,fit_error numbers");
    if (!std::isfinite(s.energy)) throw Error(path, "line " + std::to_string(number) + ": the energy is not finite");
    history.samples.push_back(s);
  }
  if (!header) throw Error(path, "not a convergence history (no header " + std::string(kHeader) + ")");
  if (history.samples.empty()) throw Error(path, "a convergence history with no steps (its header alone)");
  return history;
}

}  // namespace dynsub
