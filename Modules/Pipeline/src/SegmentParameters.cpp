#include "dynsub/SegmentParameters.h"

#include <cctype>
#include <cmath>
#include <sstream>

#include "dynsub/Error.h"
#include "dynsub/Integrator.h"
#include "dynsub/LandmarkConvention.h"

namespace dynsub {

namespace {

using P = SegmentParameters;

std::string number(double v) {
  std::ostringstream out;
  out << v;
  return out.str();
}

std::string methodName(const P& p) { return p.segment.edges.method == EdgeMethod::GradientMagnitude ? "gradient" : "edges"; }
void setMethod(P& p, const std::string& name) {
  p.segment.edges.method = name == "gradient" ? EdgeMethod::GradientMagnitude : EdgeMethod::MongaDeriche;
}
std::string referenceName(const P& p) { return p.segment.edges.reference == EdgeReference::Image ? "image" : "landmarks"; }
void setReference(P& p, const std::string& name) {
  p.segment.edges.reference = name == "image" ? EdgeReference::Image : EdgeReference::Landmarks;
}
std::string schemeName(const P& p) { return toString(p.segment.simulation.integrator.scheme); }
void setScheme(P& p, const std::string& name) { p.segment.simulation.integrator.scheme = parseIntegrationScheme(name); }
std::string solverName(const P& p) { return toString(p.segment.simulation.integrator.solver); }
void setSolver(P& p, const std::string& name) { p.segment.simulation.integrator.solver = parseLinearSolver(name); }

Parameter row(std::string name, std::string label, std::string unit, std::string group, std::string help,
              decltype(Parameter::value) value, double low = -std::numeric_limits<double>::infinity(),
              double high = std::numeric_limits<double>::infinity(), double step = 0) {
  Parameter p;
  p.name = std::move(name);
  p.label = std::move(label);
  p.unit = std::move(unit);
  p.group = std::move(group);
  p.help = std::move(help);
  p.value = value;
  p.low = low;
  p.high = high;
  p.step = step;
  return p;
}

// The table. Its order is the order of the options' help, of a plan's
// keys in the documentation, of the Slicer panel and of report.json.
std::vector<Parameter> table() {
  std::vector<Parameter> t;
  const auto add = [&t](Parameter p) { t.push_back(std::move(p)); };

  // Edges.
  add(row("potential", "Edges", "", "Edges",
       "edges (the distance to edges a 3D Monga-Deriche detector finds) or gradient (the smoothed gradient "
       "magnitude)",
       Parameter::Choice{{"edges", "gradient"}, methodName, setMethod}));
  add(row("sigma", "Edge smoothing", "mm", "Edges", "Gaussian smoothing of the edge detector",
       [](P& p) -> double& { return p.segment.edges.sigma; }, 0.1, 20, 0.1));
  add(row("edge_reference", "Edge reference", "", "Edges",
       "What the edge thresholds are fractions of: landmarks (the median over the landmarks of the strongest "
       "gradient within the edge landmark reach of each, the boundary the expert marked; the image's without "
       "landmarks; an error if the landmarks are on no edge) or image (the 99th-percentile gradient)",
       Parameter::Choice{{"landmarks", "image"}, referenceName, setReference}));
  const EdgeOptions edgeDefaults;
  add(row("edge_low", "Edge low threshold", "", "Edges",
       "Hysteresis low threshold, a fraction of the edge reference (by default " +
           number(edgeDefaults.ofLandmarks.low) + " of the landmarks', " + number(edgeDefaults.ofImage.low) +
           " of the image's)",
       [](P& p) -> std::optional<double>& { return p.edgeLow; }, 0, 10, 0.05));
  add(row("edge_high", "Edge high threshold", "", "Edges",
       "Hysteresis high threshold, the same unit (by default " + number(edgeDefaults.ofLandmarks.high) +
           " of the landmarks', " + number(edgeDefaults.ofImage.high) + " of the image's)",
       [](P& p) -> std::optional<double>& { return p.edgeHigh; }, 0, 10, 0.05));
  add(row("edge_landmark_reach", "Edge reach of a point", "mm", "Edges",
       "With the landmarks as the edge reference, a landmark's edge is the strongest gradient this close",
       [](P& p) -> double& { return p.segment.edges.landmarkReach; }, 0.1, 20, 0.1));
  add(row("capture_range", "Capture range", "mm", "Edges", "How far from an edge the image still pulls the surface",
       [](P& p) -> double& { return p.segment.edges.captureRange; }, 0.5, 100, 0.5));

  // Forces.
  add(row("image_force", "Image force", "N/mm^2", "Forces", "The pull toward edges, k, per unit of surface",
       [](P& p) -> double& { return p.segment.imageForce; }, 0, 100, 0.01));
  add(row("landmark_stiffness", "Point stiffness", "N/mm", "Forces", "Spring stiffness of each landmark",
       [](P& p) -> double& { return p.segment.landmarkStiffness; }, 1e-6, 10000, 0.5));
  add(row("landmark_dead_zone", "Point dead zone", "mm", "Forces",
       "A landmark's spring pulls only where the surface is farther than this from the click (a click's error; "
       "0: a plain spring)",
       [](P& p) -> double& { return p.segment.landmarkDeadZone; }, 0, 20, 0.1));
  add(row("inflation", "Inflation", "N/mm^2", "Forces",
       "Pressure along the normal: positive grows the surface, negative shrinks it",
       [](P& p) -> double& { return p.segment.inflation; }, -10, 10, 0.01));
  add(row("region_pressure", "Region pressure", "N/mm^2", "Forces",
       "A pressure gated by appearance (0: off): it grows the surface through tissue like the initial model's "
       "inside and pushes it back where the intensity is unlike it",
       [](P& p) -> double& { return p.segment.regionPressure; }, -10, 10, 0.01));
  add(row("region_window", "Region window", "spreads", "Forces",
       "With the region pressure: how unlike the inside (robust spreads from its median) the intensity is where "
       "the pressure turns to push back",
       [](P& p) -> double& { return p.segment.regionWindow; }, 0.1, 50, 0.1));
  add(row("margin", "Margin", "mm", "Forces",
       "The region of interest around the initial model and the landmarks; no image force acts beyond it",
       [](P& p) -> double& { return p.segment.margin; }, 0, 200, 1));

  // Refinement.
  add(row("landmark_tolerance", "Point tolerance", "mm", "Refinement",
       "The control mesh is refined at equilibrium while a landmark is farther than this from the surface",
       [](P& p) -> double& { return p.segment.landmarkTolerance; }, 0, 50, 0.05));
  add(row("max_level", "Refinements", "", "Refinement", "Global refinements of the control mesh allowed",
       [](P& p) -> int& { return p.segment.simulation.maxLevel; }, 0, 6, 1));
  add(row("elasticity_per_level", "Elasticity per level", "", "Refinement",
       "Tension and rigidity at level g are multiplied by this to the power g, so that finer levels bend "
       "more freely",
       [](P& p) -> double& { return p.segment.simulation.elasticityPerLevel; }, 0.01, 1, 0.05));

  // Slice ends.
  Parameter sliceEnds = row("slice_ends", "Slice ends", "", "Slice ends",
                      "For landmarks on slices: follow the tissue between the clicked slices beyond them and add "
                      "soft springs where it ends, so that the structure's unclicked ends are reached (off when "
                      "the clicks reach both ends: the march can then go on into like tissue; an atlas start "
                      "does not march: its atlas gives the ends)",
                      [](P& p) -> bool& { return p.segment.sliceEnds.enabled; });
  sliceEnds.opposite = Parameter::Opposite{
      "pointsReachEnds", "Points reach both ends",
      "Check when the boundary points include the structure's first and last slices. Unchecked, the surface "
      "is carried past the outermost slices with points to where the structure's tissue ends, since experts "
      "seldom place points there; when the points already reach the ends, that can carry it on into like "
      "tissue. An atlas start never does: its atlas gives the ends."};
  add(sliceEnds);
  add(row("end_pressure", "End pressure", "N/mm^2", "Slice ends",
       "With slice ends: the pressure beyond the outermost clicked slices, at full strength, that grows the "
       "surface through tissue like that just inside the clicks and pushes it back from tissue like that just "
       "outside them (0: none)",
       [](P& p) -> double& { return p.segment.sliceEnds.pressure; }, 0, 10, 0.05));
  add(row("slice_ends_window", "End window", "spreads", "Slice ends",
       "The intensities the march follows: this many robust spreads either side of the median inside the "
       "initial model",
       [](P& p) -> double& { return p.segment.sliceEnds.window; }, 0.1, 50, 0.1));
  add(row("slice_ends_disk", "End disk", "", "Slice ends",
       "The radius of the disk marched, a fraction of the end slice's rms radius",
       [](P& p) -> double& { return p.segment.sliceEnds.disk; }, 0.01, 10, 0.05));
  add(row("slice_ends_reach", "End reach", "", "Slice ends",
       "The march's longest, a fraction of the clicked span",
       [](P& p) -> double& { return p.segment.sliceEnds.reach; }, 0.01, 10, 0.05));
  add(row("slice_ends_gap", "End gap", "mm", "Slice ends", "No spring for a shorter march",
       [](P& p) -> double& { return p.segment.sliceEnds.gap; }, 0, 100, 0.5));
  add(row("slice_ends_stiffness", "End stiffness", "N/mm", "Slice ends", "The stiffness of each spring at an end",
       [](P& p) -> double& { return p.segment.sliceEnds.stiffness; }, 0.01, 10000, 0.5));
  Parameter taper = row("slice_ends_taper", "End taper", "", "Slice ends",
                  "Also springs halfway to an end, the end slice's clicks drawn in (an ellipsoid's taper), unless "
                  "the clicked cross-sections widen fast toward it",
                  [](P& p) -> bool& { return p.segment.sliceEnds.taper; });
  taper.opposite = Parameter::Opposite{"sliceEndsWithoutTaper", "No taper springs",
                                       "Only the springs at the ends, none halfway to them."};
  add(taper);
  add(row("slice_ends_end_level", "End level", "", "Slice ends",
       "How far the march's window moves from the initial model's median intensity to the end slice's own "
       "(0: not at all, 1: centred on the end's; where the two are within the window of each other)",
       [](P& p) -> double& { return p.segment.sliceEnds.endLevel; }, 0, 1, 0.1));
  add(row(
      "slice_ends_end_level_at_reach", "End level at reach", "", "Slice ends",
      "Where the march found no end within its reach, it marches again with its window this far from the "
      "initial model's median to the end slice's own (as End level; equal to it: no second march)",
      [](P& p) -> double& { return p.segment.sliceEnds.endLevelAtReach; }, 0, 1, 0.1));
  add(row("slice_ends_spring_at_reach", "Spring at reach", "", "Slice ends",
       "A spring also where the march ended at its reach, not at an intensity change",
       [](P& p) -> bool& { return p.segment.sliceEnds.springAtReach; }));

  // Start.
  add(row("initial_fraction", "Initial size", "", "Start",
       "The initial model inside the landmarks' (or a seed region's boundary points') PCA ellipsoid: this "
       "fraction of its semi-axes",
       [](P& p) -> double& { return p.initialFraction; }, 0.05, 1, 0.05));
  Parameter convention = row(
      "check_convention", "Convention check", "", "Start",
      "With 4 or more boundary points: refuse them when, with x and y negated (RAS read as LPS, or the reverse) "
      "or with x alone negated (left and right swapped), they lie on image edges much stronger than theirs or "
      "much better facing their shape",
      [](P& p) -> bool& { return p.checkConvention; });
  convention.opposite = Parameter::Opposite{
      "noConventionCheck", "Skip the convention check",
      "Check to keep points that look mirrored: by default, points whose RAS/LPS flip or left-right mirror lies "
      "on much stronger edges are refused as read in the wrong coordinate convention."};
  add(convention);
  add(row("seed_window", "Seed window", "spreads", "Start",
       "With a seed click: the intensity window grown through, in robust spreads (1.4826 MAD) of the "
       "intensities near the click either side of their median",
       [](P& p) -> double& { return p.seed.window; }, 0.1, 50, 0.5));
  add(row("seed_opening", "Seed opening", "mm", "Start",
       "With a seed click: the radius of the opening that cuts thin bridges to like tissue (0: none)",
       [](P& p) -> double& { return p.seed.opening; }, 0, 20, 0.5));
  add(row("seed_reach", "Seed reach", "mm", "Start", "With a seed click: how far the region may grow from it",
       [](P& p) -> double& { return p.seed.reach; }, 1, 500, 5));
  add(row("seed_stats_radius", "Seed statistics radius", "mm", "Start",
       "With a seed click: the radius around it whose intensities set the window",
       [](P& p) -> double& { return p.seed.statsRadius; }, 0.1, 50, 0.5));
  add(row("seed_boundary_points", "Seed boundary points", "", "Start",
       "With a seed click: at most this many of the region's boundary points are kept",
       [](P& p) -> int& { return p.seed.boundaryPoints; }, 4, 100000, 1));
  add(row("seed_stiffness", "Seed stiffness", "N/mm", "Start",
       "With a seed click and no landmarks: the stiffness of the springs to the region's boundary points",
       [](P& p) -> double& { return p.seed.stiffness; }, 0, 10000, 0.5));

  add(row("barrier_stiffness", "Barrier stiffness", "N/mm^3", "Forces",
       "With several structures: how hard each pushes the others' surfaces out of its territory, per mm "
       "they went in (0: no barrier; the joined labelmap still gives each voxel one structure)",
       [](P& p) -> double& { return p.barrierStiffness; }, 0, 1000, 0.5));

  // Atlas.
  add(row("prior_points", "Prior points", "", "Atlas",
       "With an atlas start: the points spread over the carried label's boundary that the prior's springs pull "
       "toward",
       [](P& p) -> int& { return p.priorPoints; }, 4, 100000, 1));
  add(row("prior_stiffness", "Prior stiffness", "N/mm", "Atlas",
       "With an atlas start: the stiffness of each prior spring (0: none; the atlas then only starts the "
       "surface)",
       [](P& p) -> double& { return p.priorStiffness; }, 0, 10000, 0.5));
  add(row("registration_smoothing", "Registration smoothing", "mm", "Atlas",
       "With an atlas start: the Gaussian (sigma) that smooths each step of the deformable registration; "
       "larger keeps the atlas's shape, smaller follows the image closer",
       [](P& p) -> double& { return p.registration.updateSigmaMm; }, 0.5, 50, 0.5));
  add(row("registration_margin", "Registration margin", "mm", "Atlas",
       "With an atlas start: the neighbourhood around the structure the deformable registration covers",
       [](P& p) -> double& { return p.registration.marginMm; }, 0, 200, 1));

  // Solver.
  add(row("scheme", "Scheme", "", "Solver",
       "How the equilibrium is reached: static (Newton steps on K p = f_p), or time integration, first-order "
       "(massless, TVCG eq. 32) or second-order (eq. 31)",
       Parameter::Choice{{"static", "first-order", "second-order"}, schemeName, setScheme}));
  add(row("solver", "Linear solver", "", "Solver",
       "Linear solver per step: cholesky (factored once per level), cg, or pcg (incomplete Cholesky)",
       Parameter::Choice{{"cholesky", "cg", "pcg"}, solverName, setSolver}));
  add(row("time_step", "Time step", "s", "Solver",
       "Time step (halved automatically on divergence, and doubled back once the energy falls)",
       [](P& p) -> double& { return p.segment.simulation.integrator.timeStep; }, 1e-6, 1e6, 0.5));
  add(row("time_step_regrowth", "Time step regrowth", "steps", "Solver",
       "After this many steps running, a halved time step is doubled again (0: never)",
       [](P& p) -> int& { return p.segment.simulation.timeStepRegrowth; }, 0, 1000000, 1));
  add(row("max_steps", "Step limit", "steps", "Solver", "Step limit per level",
       [](P& p) -> int& { return p.segment.simulation.equilibrium.maxSteps; }, 1, 1000000, 10));
  add(row("coarse_level_factor", "Coarse level factor", "", "Solver",
       "The equilibrium tolerances of the levels below the last, multiplied by this",
       [](P& p) -> double& { return p.segment.simulation.equilibrium.coarseLevelFactor; }, 1, 1000, 0.5));
  add(row("mass", "Mass", "kg", "Solver", "Mass density mu, per unit parametric area",
       [](P& p) -> double& { return p.segment.simulation.material.mass; }, 0, 1e6, 0.1));
  add(row("damping", "Damping", "kg/s", "Solver", "Damping density gamma, per unit parametric area",
       [](P& p) -> double& { return p.segment.simulation.material.damping; }, 0, 1e6, 0.5));
  add(row("tension", "Tension", "N/mm", "Solver",
       "Tension alpha11 = alpha22 per unit parametric area (a membrane: resists stretching)",
       [](P& p) -> double& { return p.segment.simulation.material.tensionU; }, 0, 1e6, 0.01));
  add(row("rigidity", "Rigidity", "N/mm", "Solver",
       "Rigidity beta11 = beta22 = beta12 / 2 per unit parametric area (a thin plate: resists bending)",
       [](P& p) -> double& { return p.segment.simulation.material.rigidityUU; }, 0, 1e6, 0.01));
  return t;
}

bool isWhole(double v) { return std::isfinite(v) && v == std::floor(v); }

// "sigma_mm (--sigma)": how errors name a row, for plans and the command line alike.
std::string nameOf(const Parameter& row) { return row.key() + " (" + row.flag() + ")"; }

// `x` (given as `value`) within the row's range, or an error naming the row.
double requireInRange(const Parameter& row, double x, const ParameterValue& value) {
  if (!(x >= row.low && x <= row.high))
    throw Error(nameOf(row) + " must be in " + number(row.low) + ".." + number(row.high) + ", got " + toText(value));
  return x;
}

}  // namespace

std::string Parameter::key() const { return unit == "mm" ? name + "_mm" : name; }

std::string Parameter::flag() const {
  std::string f = "--" + name;
  for (char& c : f)
    if (c == '_') c = '-';
  return f;
}

std::string Parameter::camelName() const {
  std::string out;
  bool upper = false;
  for (const char c : name) {
    if (c == '_') {
      upper = true;
      continue;
    }
    out += upper ? static_cast<char>(std::toupper(static_cast<unsigned char>(c))) : c;
    upper = false;
  }
  return out;
}

const std::vector<ParameterGroup>& segmentParameterGroups() {
  static const std::vector<ParameterGroup> groups = {
      {"Edges", "What the image force pulls toward.", false},
      {"Forces", "What moves the surface besides the edges.", false},
      {"Refinement", "When the control mesh is refined.", false},
      {"Slice ends", "The structure's ends beyond the outermost clicked slices.", true},
      {"Start", "The initial model, from the landmarks or from a click inside.", true},
      {"Atlas", "The start from an atlas registered to the image, and its prior.", true},
      {"Solver", "How the equilibrium is reached, and the surface's material.", true}};
  return groups;
}

const std::vector<Parameter>& segmentParameters() {
  static const std::vector<Parameter> rows = table();
  return rows;
}

const Parameter* findSegmentParameter(const std::string& key) {
  for (const Parameter& p : segmentParameters())
    if (p.key() == key) return &p;
  return nullptr;
}

ParameterValue parameterValue(const SegmentParameters& parameters, const Parameter& parameter) {
  // The accessors give a reference to write through; reading needs no copy.
  P& p = const_cast<P&>(parameters);
  return std::visit(
      [&](const auto& access) -> ParameterValue {
        using A = std::decay_t<decltype(access)>;
        if constexpr (std::is_same_v<A, Parameter::Choice>) return access.get(p);
        else if constexpr (std::is_same_v<A, Parameter::OptionalReal>) {
          const std::optional<double>& v = access(p);
          return v ? ParameterValue(*v) : ParameterValue();
        } else return access(p);
      },
      parameter.value);
}

void setParameter(SegmentParameters& p, const Parameter& parameter, const ParameterValue& value) {
  const std::string what = nameOf(parameter);
  const auto inRange = [&](double v) { return requireInRange(parameter, v, value); };
  const auto real = [&]() -> double {
    if (const double* d = std::get_if<double>(&value)) return inRange(*d);
    if (const int* i = std::get_if<int>(&value)) return inRange(*i);
    throw Error(what + " must be a number, got " + toText(value));
  };
  std::visit(
      [&](const auto& access) {
        using A = std::decay_t<decltype(access)>;
        if constexpr (std::is_same_v<A, Parameter::Real>) {
          access(p) = real();
        } else if constexpr (std::is_same_v<A, Parameter::OptionalReal>) {
          if (std::holds_alternative<std::monostate>(value)) access(p).reset();
          else access(p) = real();
        } else if constexpr (std::is_same_v<A, Parameter::Whole>) {
          const double v = std::holds_alternative<int>(value) ? std::get<int>(value)
                           : std::holds_alternative<double>(value)
                               ? std::get<double>(value)
                               : std::numeric_limits<double>::quiet_NaN();
          if (!isWhole(v)) throw Error(what + " must be a whole number, got " + toText(value));
          access(p) = static_cast<int>(inRange(v));
        } else if constexpr (std::is_same_v<A, Parameter::Switch>) {
          const bool* b = std::get_if<bool>(&value);
          if (!b) throw Error(what + " must be true or false, got " + toText(value));
          access(p) = *b;
        } else {
          const std::string* s = std::get_if<std::string>(&value);
          std::string names;
          for (const std::string& n : access.names) names += (names.empty() ? "" : ", ") + n;
          bool known = false;
          for (const std::string& n : access.names) known = known || (s && *s == n);
          if (!known) throw Error(what + " must be one of " + names + ", got " + toText(value));
          access.set(p, *s);
        }
      },
      parameter.value);
}

std::string toText(const ParameterValue& value) {
  return std::visit(
      [](const auto& v) -> std::string {
        using V = std::decay_t<decltype(v)>;
        if constexpr (std::is_same_v<V, std::monostate>) return "unset";
        else if constexpr (std::is_same_v<V, bool>) return v ? "true" : "false";
        else if constexpr (std::is_same_v<V, std::string>) return v;
        else if constexpr (std::is_same_v<V, double>) return number(v);
        else return std::to_string(v);
      },
      value);
}

namespace {

// Each number within its row's range (a plan's values are checked as they
// are set, the command line's by its options; this holds for a caller that
// fills the struct itself).
void checkRanges(const SegmentParameters& parameters) {
  for (const Parameter& row : segmentParameters()) {
    const ParameterValue v = parameterValue(parameters, row);
    const double* real = std::get_if<double>(&v);
    const int* whole = std::get_if<int>(&v);
    if (!real && !whole) continue;
    requireInRange(row, real ? *real : *whole, v);
  }
}

// segmentOptions(), its errors as found.
SegmentOptions checkedOptions(const SegmentParameters& parameters, bool pointsOnBoundary) {
  checkRanges(parameters);
  checkSeedOptions(parameters.seed);
  checkAtlasRegistrationOptions(parameters.registration);
  SegmentOptions o = parameters.segment;
  EdgeOptions& edges = o.edges;
  // Landmarks off every edge are an error, not a silent switch to the image's reference (EdgePotential.h).
  Hysteresis& thresholds =
      edges.reference == EdgeReference::Landmarks && pointsOnBoundary ? edges.ofLandmarks : edges.ofImage;
  if (parameters.edgeLow) thresholds.low = *parameters.edgeLow;
  if (parameters.edgeHigh) thresholds.high = *parameters.edgeHigh;
  // Said here, where it is known which was given and of which reference.
  if (thresholds.low > thresholds.high)
    throw Error("edge_low (--edge-low) is " + number(thresholds.low) + (parameters.edgeLow ? "" : " (its default)") +
                " and edge_high (--edge-high) " + number(thresholds.high) +
                (parameters.edgeHigh ? "" : " (its default)") +
                ": the low threshold must not exceed the high one (both are fractions of " +
                (&thresholds == &edges.ofLandmarks ? "the landmarks' median gradient)"
                                                   : "the image's 99th-percentile gradient)"));
  Material& m = o.simulation.material;
  m.tensionV = m.tensionU;
  m.rigidityVV = m.rigidityUU;
  m.rigidityUV = 2 * m.rigidityUU;
  checkSegmentOptions(o);
  return o;
}

}  // namespace

SegmentOptions segmentOptions(const SegmentParameters& parameters, bool pointsOnBoundary) {
  // Every value here is an option someone gave.
  return asUsageError([&] { return checkedOptions(parameters, pointsOnBoundary); });
}

void checkSegmentParameters(const SegmentParameters& parameters) {
  // The thresholds are checked against both references they may go to.
  segmentOptions(parameters, true);
  segmentOptions(parameters, false);
}

}  // namespace dynsub
