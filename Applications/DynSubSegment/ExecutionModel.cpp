#include "ExecutionModel.h"

#include <iomanip>
#include <optional>
#include <set>
#include <sstream>
#include <stdexcept>
#include <type_traits>

#include <CLI/CLI.hpp>

#include "CommandLine.h"
#include "dynsub/TextFields.h"

namespace dynsub::slicer {

namespace {

std::string escaped(const std::string& text) {
  std::string out;
  for (const char c : text) {
    if (c == '&') out += "&amp;";
    else if (c == '<') out += "&lt;";
    else if (c == '>') out += "&gt;";
    else if (c == '"') out += "&quot;";
    else out += c;
  }
  return out;
}

// The default a plain value shows in Slicer's panel: the target's value now.
std::string defaultOf(const Parameter& p) {
  if (!p.channel.empty() || p.index >= 0) return "";
  if (const auto* d = std::get_if<double*>(&p.target)) return number(**d);
  if (const auto* i = std::get_if<int*>(&p.target)) return std::to_string(**i);
  if (const auto* s = std::get_if<std::string*>(&p.target)) return **s;
  if (const auto* b = std::get_if<bool*>(&p.target)) return **b ? "true" : "false";
  return "";
}

// The numbers in a word of a point ("[-16.5," or "19.0," or "1,2,3"), or
// nothing when a part of it is not a number, or is missing ("17.5,,21",
// ",17.5,21": only the comma that ends a word, before the next, may have
// nothing after it).
std::optional<std::vector<std::string>> pointNumbers(const std::string& word) {
  std::string text = word;
  for (char& c : text)
    if (c == '[' || c == ']' || c == '(' || c == ')') c = ' ';
  const std::vector<std::string> items = dynsub::splitItems(text, ',');
  std::vector<std::string> numbers;
  for (std::size_t i = 0; i < items.size(); ++i) {
    std::istringstream in(items[i]);
    std::size_t found = 0;
    for (std::string part; in >> part; ++found) {
      double value = 0;
      if (!dynsub::parseNumber(part, value)) return std::nullopt;
      numbers.push_back(part);
    }
    if (found == 0 && i + 1 < items.size()) return std::nullopt;
  }
  return numbers;
}

void tag(std::ostringstream& out, const char* indent, const std::string& name, const std::string& text) {
  out << indent << '<' << name << '>' << escaped(text) << "</" << name << ">\n";
}

}  // namespace

std::string number(double value) {
  std::ostringstream out;
  out << std::setprecision(12) << value;
  return out.str();
}

std::string descriptor(const Module& module) {
  std::ostringstream out;
  out << "<?xml version=\"1.0\" encoding=\"utf-8\"?>\n<executable>\n";
  tag(out, "  ", "category", module.category);
  tag(out, "  ", "title", module.title);
  tag(out, "  ", "description", module.description);
  tag(out, "  ", "version", module.version);
  if (!module.documentationUrl.empty()) tag(out, "  ", "documentation-url", module.documentationUrl);
  tag(out, "  ", "license", module.license);
  tag(out, "  ", "contributor", module.contributor);
  tag(out, "  ", "acknowledgements", module.acknowledgements);
  for (const ParameterGroup& group : module.groups) {
    out << "  <parameters" << (group.advanced ? " advanced=\"true\"" : "") << ">\n";
    tag(out, "    ", "label", group.label);
    tag(out, "    ", "description", group.description);
    for (const Parameter& p : group.parameters) {
      out << "    <" << p.element << (p.attributes.empty() ? "" : " " + p.attributes) << ">\n";
      tag(out, "      ", "name", p.name);
      tag(out, "      ", "label", p.label);
      tag(out, "      ", "description", p.description);
      if (p.index >= 0) tag(out, "      ", "index", std::to_string(p.index));
      else tag(out, "      ", "longflag", "--" + p.flag);
      if (!p.channel.empty()) tag(out, "      ", "channel", p.channel);
      const std::string value = defaultOf(p);
      if (!value.empty()) tag(out, "      ", "default", value);
      for (const std::string& choice : p.choices) tag(out, "      ", "element", choice);
      if (!p.minimum.empty() || !p.maximum.empty() || !p.step.empty()) {
        out << "      <constraints>\n";
        if (!p.minimum.empty()) tag(out, "        ", "minimum", p.minimum);
        if (!p.maximum.empty()) tag(out, "        ", "maximum", p.maximum);
        if (!p.step.empty()) tag(out, "        ", "step", p.step);
        out << "      </constraints>\n";
      }
      out << "    </" << p.element << ">\n";
    }
    out << "  </parameters>\n";
  }
  out << "</executable>\n";
  return out.str();
}

std::vector<std::string> withJoinedPoints(const Module& module, int argc, const char* const* argv) {
  std::set<std::string> pointFlags;
  for (const ParameterGroup& group : module.groups)
    for (const Parameter& p : group.parameters)
      if (p.element == "point" && p.index < 0) pointFlags.insert("--" + p.flag);
  const std::vector<std::string> words(argv + 1, argv + argc);
  std::vector<std::string> joined;
  for (std::size_t i = 0; i < words.size(); ++i) {
    joined.push_back(words[i]);
    if (!pointFlags.count(words[i])) continue;
    std::vector<std::string> numbers;
    std::size_t next = i + 1;
    for (; next < words.size() && numbers.size() < 3; ++next) {
      const auto found = pointNumbers(words[next]);
      if (!found || found->empty() || numbers.size() + found->size() > 3) break;
      numbers.insert(numbers.end(), found->begin(), found->end());
    }
    if (numbers.size() != 3) continue;
    joined.push_back(numbers[0] + "," + numbers[1] + "," + numbers[2]);
    i = next - 1;
  }
  return joined;
}

void addOptions(CLI::App& app, const Module& module) {
  for (const ParameterGroup& group : module.groups) {
    for (const Parameter& p : group.parameters) {
      const std::string name = p.index >= 0 ? p.name : "--" + p.flag;
      if (bool* const* flag = std::get_if<bool*>(&p.target); flag && (**flag || p.index >= 0))
        throw std::logic_error(p.name + ": a <boolean> is a flag that defaults to false");
      CLI::Option* option = std::visit(
          [&](auto* target) -> CLI::Option* {
            // A boolean is its flag alone, as Slicer passes it when checked.
            if constexpr (std::is_same_v<decltype(target), bool*>) return app.add_flag(name, *target, p.description);
            else return app.add_option(name, *target, p.description);
          },
          p.target);
      if (std::holds_alternative<std::vector<std::string>*>(p.target)) {
        // One value per occurrence, so that "--seed a --seed b IMAGE" leaves IMAGE positional.
        option->expected(1)->multi_option_policy(CLI::MultiOptionPolicy::TakeAll);
      }
      if (p.index >= 0) option->required();
      if (!p.choices.empty()) option->check(CLI::IsMember(p.choices));
      if (!p.minimum.empty() && !p.maximum.empty())
        option->check(dynsub::app::numberBetween(std::stod(p.minimum), std::stod(p.maximum),
                                                 std::holds_alternative<int*>(p.target)));
      const std::string value = defaultOf(p);
      if (!value.empty() && !std::holds_alternative<bool*>(p.target)) option->default_str(value);
    }
  }
}

}  // namespace dynsub::slicer
