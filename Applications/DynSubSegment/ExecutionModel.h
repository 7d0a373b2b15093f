#pragma once
// A 3D Slicer CLI module's parameters, declared once: the same table prints
// the Execution Model descriptor (`--xml`, the XML Slicer and nipype read to
// build the module's panel) and defines the command-line options Slicer then
// passes, so the two cannot drift apart.
#include <string>
#include <variant>
#include <vector>

namespace CLI {
class App;
}

namespace dynsub::slicer {

struct Parameter {
  std::string element;     // the descriptor's tag: image, point, file, geometry, double, integer, ...
  std::string attributes;  // e.g. type="label" reference="inputVolume"
  std::string name;        // the parameter's name in the descriptor
  std::string flag;        // long flag without "--"; empty for a positional (indexed) parameter
  std::string label, description;
  // Where the value goes. A vector takes one value per occurrence of the flag
  // (Slicer's multiple="true" points: "--seed x,y,z" once per point).
  // A bool is a <boolean>: Slicer passes its flag alone when it is checked,
  // and nothing when not, so its default must be false.
  std::variant<std::string*, std::vector<std::string>*, double*, int*, bool*> target;
  std::string channel;                  // input or output for data parameters; empty for plain values
  std::string minimum, maximum, step;   // constraints of a number; empty: none
  std::vector<std::string> choices;     // the elements of an enumeration
  int index = -1;                       // position of a positional parameter
};

struct ParameterGroup {
  std::string label, description;
  bool advanced = false;
  std::vector<Parameter> parameters;
};

struct Module {
  std::string category, title, description, version, documentationUrl, license, contributor, acknowledgements;
  std::vector<ParameterGroup> groups;
};

// A number as the descriptor writes it: to 12 significant digits.
std::string number(double value);

// The descriptor, starting with "<?xml". Each plain value's default is the
// target's current value.
std::string descriptor(const Module& module);

// The program's arguments (without its name), with each point's value as
// one "x,y,z". Slicer passes a point so; nipype's generated interface passes
// "[x, y, z]" for each of several points and "x y z" for a single one, which
// the shell splits into three words. After a point's flag, words are joined
// while they hold numbers, up to three; anything else is left to the option's
// own error.
std::vector<std::string> withJoinedPoints(const Module& module, int argc, const char* const* argv);

// One CLI11 option per parameter (positional for an index), with the
// constraints as checks and the targets' current values as defaults.
void addOptions(CLI::App& app, const Module& module);

}  // namespace dynsub::slicer
