#include "CommandLine.h"

#include <algorithm>

#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <iomanip>
#include <sstream>
#include <variant>

#include <CLI/CLI.hpp>

#include "dynsub/Error.h"
#include "dynsub/TextFields.h"

namespace dynsub::app {

namespace {

// Whether `text` is a whole number as written in base 10: a sign, then
// digits without a leading 0. CLI11 stores an integer option through
// strtoll in base 0, which reads "010" as octal 8 and "0x10" as 16; such
// text is refused rather than checked as one value and stored as another.
bool decimalWholeNumber(const std::string& text) {
  const std::size_t digits = !text.empty() && (text[0] == '+' || text[0] == '-') ? 1 : 0;
  if (digits == text.size() || (text[digits] == '0' && text.size() > digits + 1)) return false;
  return std::all_of(text.begin() + digits, text.end(), [](char c) { return c >= '0' && c <= '9'; });
}

// `value` as written in a message: in full up to 7 characters (1024, 0.001),
// in short scientific form beyond (1e+12).
std::string shortNumber(double value) {
  std::ostringstream full, brief;
  full << std::setprecision(15) << value;
  brief << value;
  return full.str().size() <= 7 ? full.str() : brief.str();
}

// The one check behind every numeric option: `text` read by strtod,
// then held to [low, high] (or (low, high] when `lowIncluded` is false), and
// to decimal digits when `whole`.
CLI::Validator numberCheck(double low, bool lowIncluded, double high, bool whole) {
  const bool closed = lowIncluded && std::isfinite(high);
  std::string range = closed ? "between " + shortNumber(low) + " and " + shortNumber(high)
                             : std::string("a finite number ") + (lowIncluded ? ">= " : "> ") + shortNumber(low);
  if (!closed && std::isfinite(high)) range += " and <= " + shortNumber(high);
  const std::string shown = std::string(whole ? "INT" : "FLOAT") +
                            (std::isfinite(high) ? std::string(" in ") + (lowIncluded ? "[" : "(") + shortNumber(low) +
                                                       " - " + shortNumber(high) + "]"
                                                 : (lowIncluded ? ">=" : ">") + shortNumber(low));
  return CLI::Validator(
      [low, lowIncluded, high, whole, range](std::string& text) -> std::string {
        const std::string quoted = "'" + text + "'";
        // Decimal notation only: strtod also reads " 5", hexadecimal "0x10" and "0x1p3".
        const bool decimal = !text.empty() && text.find_first_not_of("0123456789+-.eE") == std::string::npos;
        char* end = nullptr;
        // A number too small for a double (1e-999) is read as strtod rounds it (0);
        // one too large (1e999) as infinite, which no range holds.
        const double value = decimal ? std::strtod(text.c_str(), &end) : 0.0;
        if (!decimal || *end != '\0' || std::isnan(value)) return quoted + " is not a number";
        if (whole && !decimalWholeNumber(text)) return quoted + " is not a whole number (write it in digits, as 12)";
        const bool inside = std::isfinite(value) && (lowIncluded ? value >= low : value > low) && value <= high;
        return inside ? std::string() : quoted + " is not " + range;
      },
      shown);
}

}  // namespace

CLI::Validator numberBetween(double low, double high, bool whole) { return numberCheck(low, true, high, whole); }
CLI::Validator positiveNumber(double largest) { return numberCheck(0.0, false, largest, false); }
CLI::Validator nonNegativeNumber(double largest) { return numberCheck(0.0, true, largest, false); }

// The material's densities and the time step end where the segmentation's
// table ends theirs (SegmentParameters.cpp): far beyond any useful value, and
// well short of products that overflow.
constexpr double kLargestMaterialValue = 1e6;

void SimulationArguments::addOptions(CLI::App& command, const SimulationOptions& defaults) {
  values = defaults;
  scheme = toString(defaults.integrator.scheme);
  solver = toString(defaults.integrator.solver);
  command.add_option("--max-level", values.maxLevel, "Refinement levels allowed (0-6)")
      ->default_val(defaults.maxLevel)
      ->check(numberBetween(0, 6, true));
  command.add_option("--scheme", scheme,
                     "How the equilibrium is reached: static (Newton steps on K p = f_p), or time integration, "
                     "first-order (massless, TVCG eq. 32) or second-order (eq. 31)")
      ->default_val(scheme)
      ->check(CLI::IsMember({"static", "first-order", "second-order"}));
  command.add_option("--solver", solver,
                     "Linear solver per step: cholesky (factored once per level), cg, or pcg (incomplete Cholesky)")
      ->default_val(solver)
      ->check(CLI::IsMember({"cholesky", "cg", "pcg"}));
  command.add_option("--time-step", values.integrator.timeStep, "Time step, s (halved automatically on divergence, and doubled back once the energy falls)")
      ->default_val(defaults.integrator.timeStep)
      ->check(positiveNumber(kLargestMaterialValue));
  command.add_option("--max-steps", values.equilibrium.maxSteps, "Step limit per level")
      ->default_val(defaults.equilibrium.maxSteps)
      ->check(numberBetween(1, 1000000, true));
  command.add_option("--mass", values.material.mass, "Mass density mu, kg per unit parametric area")
      ->default_val(defaults.material.mass)
      ->check(nonNegativeNumber(kLargestMaterialValue));
  command.add_option("--damping", values.material.damping, "Damping density gamma, kg/s per unit parametric area")
      ->default_val(defaults.material.damping)
      ->check(nonNegativeNumber(kLargestMaterialValue));
  command.add_option("--tension", values.material.tensionU,
                     "Tension alpha11 = alpha22, N/mm per unit parametric area (membrane: resists stretching)")
      ->default_val(defaults.material.tensionU)
      ->check(nonNegativeNumber(kLargestMaterialValue));
  command.add_option("--rigidity", values.material.rigidityUU,
                     "Rigidity beta11 = beta22 = beta12/2, N/mm per unit parametric area (thin plate: resists bending)")
      ->default_val(defaults.material.rigidityUU)
      ->check(nonNegativeNumber(kLargestMaterialValue));
}

SimulationOptions SimulationArguments::apply(SimulationOptions base) const {
  base.maxLevel = values.maxLevel;
  base.relaxations = values.relaxations;
  base.integrator.scheme = parseIntegrationScheme(scheme);
  base.integrator.solver = parseLinearSolver(solver);
  base.integrator.timeStep = values.integrator.timeStep;
  base.equilibrium.maxSteps = values.equilibrium.maxSteps;
  base.material.mass = values.material.mass;
  base.material.damping = values.material.damping;
  base.material.tensionU = base.material.tensionV = values.material.tensionU;
  base.material.rigidityUU = base.material.rigidityVV = values.material.rigidityUU;
  base.material.rigidityUV = 2.0 * values.material.rigidityUU;
  asUsageError([&] { checkSimulationOptions(base); });  // first-order without damping, say
  return base;
}

void addSegmentParameterOptions(CLI::App& command, SegmentParameters& parameters) {
  SegmentParameters* p = &parameters;
  for (const Parameter& row : segmentParameters()) {
    const std::string help = row.help + (row.unit.empty() ? "" : " (" + row.unit + ")");
    const std::string shown = toText(parameterValue(parameters, row));
    CLI::Option* option = std::visit(
        [&](const auto& access) -> CLI::Option* {
          using A = std::decay_t<decltype(access)>;
          if constexpr (std::is_same_v<A, Parameter::Choice>) {
            return command
                .add_option_function<std::string>(
                    row.flag(), [p, set = access.set](const std::string& v) { set(*p, v); }, help)
                ->check(CLI::IsMember(access.names));
          } else if constexpr (std::is_same_v<A, Parameter::OptionalReal>) {
            return command
                .add_option_function<double>(
                    row.flag(), [p, access](double v) { access(*p) = v; }, help)
                ->check(numberBetween(row.low, row.high, false));
          } else if constexpr (std::is_same_v<A, Parameter::Switch>) {
            return command.add_option(row.flag(), access(parameters), help);
          } else {
            using Value = std::remove_reference_t<decltype(access(parameters))>;
            return command.add_option(row.flag(), access(parameters), help)
                ->check(numberBetween(row.low, row.high, std::is_integral_v<Value>));
          }
        },
        row.value);
    if (!std::holds_alternative<Parameter::OptionalReal>(row.value)) option->default_str(shown);
    option->group(row.group);
  }
}

ProgressLine::ProgressLine() : terminal_(isatty(fileno(stderr)) != 0) {}

ProgressCallback ProgressLine::callback() {
  if (!terminal_) return nullptr;
  return [this](const Progress& p) {
    if (p.step % 5 != 1) return;
    std::fprintf(stderr, "\rlevel %d  step %5d  energy %-12.6g  motion %-10.3g mm ", p.level, p.step, p.energy,
                 p.motion);
    std::fflush(stderr);
    written_ = true;
  };
}

void ProgressLine::finish() {
  if (written_) std::fprintf(stderr, "\n");
  written_ = false;
}

std::string didYouMean(const CLI::App& app, const std::vector<std::string>& words) {
  const CLI::App* command = &app;
  const std::vector<const CLI::App*> subcommands = app.get_subcommands([](const CLI::App*) { return true; });
  if (!subcommands.empty()) {
    // The command is the first word that is not an option.
    const auto named = std::find_if(words.begin(), words.end(), [](const std::string& w) { return w.rfind('-', 0) != 0; });
    if (named == words.end()) return "";
    std::vector<std::string> names;
    for (const CLI::App* sub : subcommands) names.push_back(sub->get_name());
    const auto known = std::find(names.begin(), names.end(), *named);
    if (known == names.end()) {
      const std::string nearest = nearestWord(*named, names);
      return nearest.empty() ? "" : "did you mean '" + nearest + "'? ('" + *named + "' is not a command)";
    }
    command = subcommands[static_cast<std::size_t>(known - names.begin())];
  }
  std::vector<std::string> flags;
  for (const CLI::Option* option : command->get_options())
    for (const std::string& name : option->get_lnames()) flags.push_back("--" + name);
  for (const std::string& word : words) {
    if (word.rfind("--", 0) != 0 || word == "--") continue;
    const std::string flag = word.substr(0, word.find('='));
    if (std::find(flags.begin(), flags.end(), flag) != flags.end()) continue;
    const std::string nearest = nearestWord(flag, flags);
    if (!nearest.empty()) return "did you mean '" + nearest + "'? ('" + flag + "' is not an option here)";
  }
  return "";
}

}  // namespace dynsub::app
