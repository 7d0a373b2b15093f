#pragma once
// Every parameter of a segmentation, each written once in the table of
// SegmentParameters.cpp: its name, where its value lives, its unit, its valid
// range, its group and its help; its default is the member's initial value.
// `dynsub segment`'s and `dynsub view`'s options, the 3D Slicer module's
// panel, the evaluation plans' "segment" keys and report.json's "parameters"
// are all made from that table, so none of them can drift from the others
// (the way Slicer's GenerateCLP makes a module's parser and its descriptor
// from one description).
#include <limits>
#include <optional>
#include <string>
#include <variant>
#include <vector>

#include "dynsub/Atlas.h"
#include "dynsub/SeedGrowth.h"
#include "dynsub/Segmentation.h"

namespace dynsub {

struct SegmentParameters {
  SegmentOptions segment;  // the evolution (Segmentation.h)
  SeedOptions seed;        // the region grown from a click inside (SeedGrowth.h)
  // The start built from the landmarks (or a seed region's boundary points):
  // this fraction of their PCA ellipsoid's semi-axes (initialFromLandmarks).
  double initialFraction = 0.5;
  // Refuse 4 or more boundary points that look read in the wrong convention
  // (LandmarkConvention.h): their RAS/LPS flip or their left-right mirror
  // lies on much stronger, better aligned edges than they do.
  bool checkConvention = true;
  // Fractions of the edge reference in use (EdgeOptions::ofLandmarks or
  // ofImage, see segmentOptions()); unset, that reference's own default.
  std::optional<double> edgeLow, edgeHigh;
  // An atlas start (Atlas.h): the registration, and the prior: soft springs
  // from this many points on the carried label's boundary, which hold the
  // surface where the image and the clicks say nothing.
  AtlasRegistrationOptions registration;
  int priorPoints = 100;
  double priorStiffness = 2.0;  // N/mm per point (0: no prior)
  // Several structures segmented together (SegmentStructures.h): the force
  // per unit area that pushes a surface out of the others' territories, per
  // mm it went in (N/mm^2 per mm).
  double barrierStiffness = 0.5;
};

// One row of the table.
struct Parameter {
  using Real = double& (*)(SegmentParameters&);
  using OptionalReal = std::optional<double>& (*)(SegmentParameters&);
  using Whole = int& (*)(SegmentParameters&);
  using Switch = bool& (*)(SegmentParameters&);
  struct Choice {
    std::vector<std::string> names;
    std::string (*get)(const SegmentParameters&);
    void (*set)(SegmentParameters&, const std::string&);
  };
  // A switch that is on by default, as a tool that can only switch things on
  // offers it: a Slicer <boolean> is a flag that defaults to false.
  struct Opposite {
    std::string name, label, help;
  };

  std::string name;   // snake_case, without the unit
  std::string label;  // a few words, for a panel
  std::string unit;   // "mm", "N/mm", ...; empty for none
  std::string group;  // one of segmentParameterGroups()
  std::string help;
  std::variant<Real, OptionalReal, Whole, Switch, Choice> value;
  // The valid range of a number, inclusive, and a step for a slider.
  double low = -std::numeric_limits<double>::infinity();
  double high = std::numeric_limits<double>::infinity();
  double step = 0;
  std::optional<Opposite> opposite;

  // report.json's and a plan's key: the name, and "_mm" for lengths ("capture_range_mm").
  std::string key() const;
  // The command-line flag: "--capture-range".
  std::string flag() const;
  // Slicer's parameter name: "captureRange".
  std::string camelName() const;
};

struct ParameterGroup {
  std::string name, help;
  bool advanced = false;  // collapsed in a panel
};

const std::vector<ParameterGroup>& segmentParameterGroups();
const std::vector<Parameter>& segmentParameters();
// The row whose key() is `key`, or null.
const Parameter* findSegmentParameter(const std::string& key);

// A value as it comes from a plan or a panel; std::monostate is an unset optional number.
using ParameterValue = std::variant<std::monostate, double, int, bool, std::string>;
ParameterValue parameterValue(const SegmentParameters& parameters, const Parameter& parameter);
// Throws dynsub::Error naming the key when the value is of another kind, not
// a whole number for a count, outside the range or not one of the choices.
void setParameter(SegmentParameters& parameters, const Parameter& parameter, const ParameterValue& value);
std::string toText(const ParameterValue& value);

// The evolution's options: `parameters.segment` with --edge-low/--edge-high
// given to the reference they are fractions of (the landmarks' when
// `pointsOnBoundary` and the reference is the landmarks, else the image's)
// and one tension and one rigidity for every direction. Throws UsageError
// for a value outside its row's range and for impossible options
// (checkSegmentOptions, checkSeedOptions): they are options someone gave.
SegmentOptions segmentOptions(const SegmentParameters& parameters, bool pointsOnBoundary);
// Whether segmentOptions() would accept the parameters whatever the inputs
// (a plan's, before any run).
void checkSegmentParameters(const SegmentParameters& parameters);

}  // namespace dynsub
