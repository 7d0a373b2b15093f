// dynsub deform: modeling by forces (TVCG §4.1, Fig. 6): springs from points in
// space to the nearest points of the limit surface pull it to a new equilibrium.
#include <algorithm>
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <sstream>

#include <CLI/CLI.hpp>

#include "CommandLine.h"
#include "Commands.h"
#include "EarlierRuns.h"
#include "dynsub/Deformation.h"
#include "dynsub/Error.h"
#include "dynsub/MeshIO.h"
#include "dynsub/ModelOutputs.h"
#include "dynsub/SpringFile.h"

namespace dynsub::app {

namespace {

struct DeformArguments {
  std::string mesh;
  std::string springs;
  std::string out;
  double stiffness = 10.0;
  bool fixBoundary = false;
  std::string refinement = "local";
  std::string restShape = "initial";
  DeformationOptions deformation;
  SimulationArguments simulation;
};

// How much more a surface must have moved than changed shape for its
// motion to be named as a whole (see runDeform).
constexpr double kMovedAsAWholeRatio = 4.0;

void runDeform(DeformArguments o) {
  const ControlMesh mesh = readControlMesh(o.mesh);
  const SpringFile springs = readSpringFile(o.springs, o.stiffness);
  const std::filesystem::path dir(o.out);
  requireInputsOutsideRun(dir, {o.mesh, o.springs});
  prepareOutputDirectory(dir);
  o.deformation.simulation = o.simulation.apply(o.simulation.values);
  o.deformation.localRefinement = o.refinement == "local";
  o.deformation.simulation.restShape = o.restShape == "initial";

  std::vector<int> boundary;
  for (int v = 0; v < mesh.vertexCount(); ++v)
    if (mesh.topology().isBoundaryVertex(v)) boundary.push_back(v);
  if (o.fixBoundary && boundary.empty()) throw Error(o.mesh, "--fix-boundary was given, but the mesh is closed");
  const std::vector<int> fixed = o.fixBoundary ? boundary : std::vector<int>();
  ProgressLine line;
  const DeformationResult result = naming(o.mesh, [&] {
    return deformSurface(mesh, springs.targets, springs.stiffness, fixed, o.deformation, line.callback());
  });
  line.finish();

  const Eigen::VectorXd& lengths = result.springLengths;
  double seconds = 0.0;
  for (const LevelSummary& l : result.levels) seconds += l.seconds;

  Report report;
  report.set("input", o.mesh);
  report.set("springs_file", o.springs);
  report.set("springs", springs.targets.rows());
  report.set("fixed_control_vertices", fixed.size());
  report.set("control_vertices", result.mesh.vertexCount());
  report.set("free_control_points", result.levels.back().freeControlPoints);
  report.set("levels", result.levels.back().level);
  report.set("iterations", result.steps);
  report.set("equilibrium", result.levels.back().converged);
  report.set("max_distance_percent", result.maxDistancePercent);
  report.set("tolerance_percent", o.deformation.tolerancePercent);
  report.set("tolerance_met", result.toleranceMet);
  report.set("diameter_mm", result.diameter);
  report.set("max_spring_length_mm", lengths.size() ? lengths.maxCoeff() : 0.0);
  report.set("mean_spring_length_mm", lengths.size() ? lengths.mean() : 0.0);
  report.set("seconds", seconds);
  report.set("turned_over_percent", result.turnedOverPercent);
  report.set("common_shift_mm", result.commonShiftMm);
  report.set("largest_departure_mm", result.largestDepartureMm);
  std::vector<Report> levels;
  for (std::size_t i = 0; i < result.levels.size(); ++i) {
    Report level = levelReport(result.levels[i], -1, -1);
    // Not refined from the level before: started again (DeformationResult::restarts).
    if (std::find(result.restarts.begin(), result.restarts.end(), static_cast<int>(i)) != result.restarts.end())
      level.set("refinement", "restarted");
    level.set("max_distance_percent", result.levelDistancesPercent[i]);
    level.set("turned_over_percent", result.levelTurnedOverPercent[i]);
    levels.push_back(level);
  }
  report.set("per_level", levels);
  std::vector<std::string> warnings;
  for (const int restart : result.restarts) {
    std::ostringstream text;
    text << std::setprecision(3) << result.levelTurnedOverPercent[restart - 1]
         << " % of the surface turned over at level " << result.levels[restart - 1].level
         << " (its normals point against the input's); the deformation started again from the input mesh refined "
         << "to level " << result.levels[restart].level;
    warnings.push_back(text.str());
  }
  if (result.turnedOverPercent > 0.0) {
    std::ostringstream text;
    text << std::setprecision(3) << result.turnedOverPercent << " % of the surface turned over (its normals point "
         << "against the input's): it folded through itself, where the springs ask for a shape the control mesh "
         << "cannot form against its elasticity";
    if (!o.deformation.simulation.restShape) text << ", which shrinks a surface without a rest shape";
    std::vector<std::string> fixes{"lower --stiffness", "add springs that hold the rest of the surface"};
    if (!o.deformation.simulation.restShape) fixes.push_back("keep the input's shape (--rest-shape initial)");
    // A finer level helps where the fold comes from a level too coarse,
    // which a restart has not already tried.
    if (result.restarts.empty() && result.levels.back().level >= o.deformation.simulation.maxLevel)
      fixes.push_back("allow a finer level (--max-level)");
    text << ". Fixes: ";
    for (std::size_t i = 0; i < fixes.size(); ++i) {
      text << (i == 0 ? "" : i + 1 < fixes.size() ? ", " : " or ") << fixes[i];
    }
    warnings.push_back(text.str());
  }
  // Refinement that ended short of the tolerance before the last level
  // allowed: a level brought the farthest target too little closer
  // (kLeastRefinementGain). (At the last level, the printed summary says
  // that the tolerance was not met.)
  const std::vector<double>& reached = result.levelDistancesPercent;
  if (!result.toleranceMet && result.levels.back().level < o.deformation.simulation.maxLevel && reached.size() >= 2) {
    std::ostringstream text;
    text << std::setprecision(3) << "the farthest target is " << result.maxDistancePercent
         << " % of the diameter from the surface, above the tolerance (" << o.deformation.tolerancePercent
         << " %): refinement stopped at level " << result.levels.back().level << ", which ";
    const double gain = 1.0 - reached.back() / reached[reached.size() - 2];
    if (gain >= 0.0)
      text << "brought it only " << 100.0 * gain << " % closer than the level before";
    else
      text << "left it " << -100.0 * gain << " % farther than the level before";
    text << " (a level must bring it " << 100.0 * kLeastRefinementGain << " % closer): the springs' pull is balanced by the surface's elasticity, which a "
         << "finer level does not weaken; stiffer springs (--stiffness, or a spring's fourth value) pull it closer";
    warnings.push_back(text.str());
  }
  // A surface nothing holds moves as a whole toward the springs rather than
  // changing shape (DeformationResult::commonShiftMm): seldom what was meant.
  // It is named when the shift exceeds the tolerance and four times the
  // largest change of shape.
  const double toleranceMm = o.deformation.tolerancePercent / 100.0 * result.diameter;
  if (fixed.empty() && result.commonShiftMm > toleranceMm &&
      result.commonShiftMm > kMovedAsAWholeRatio * result.largestDepartureMm) {
    std::ostringstream text;
    text << std::setprecision(3) << "the surface moved as a whole by " << result.commonShiftMm
         << " mm, changing its shape by at most " << result.largestDepartureMm
         << " mm: nothing holds it away from the springs, and a translation costs its elasticity nothing. To "
         << "shape one region, hold the rest: " << (boundary.empty() ? "" : "--fix-boundary, or ")
         << "springs whose targets lie on the surface where it should stay";
    warnings.push_back(text.str());
  }
  const TriangleSurface surface = outputSurface(result.mesh);
  report.set("self_intersection", selfIntersectionReport(surface, "", warnings));
  report.set("warnings", warnings);
  Report parameters = simulationReport(o.deformation.simulation);
  parameters.set("default_spring_stiffness", o.stiffness);
  parameters.set("fix_boundary", o.fixBoundary);
  parameters.set("refinement", result.localRefinement ? "local" : "global");
  parameters.set("rest_shape", o.restShape);
  report.set("parameters", parameters);

  writeModelOutputs(dir, result.mesh, surface, report, [&dir](OutputSet& outputs) { retireEarlierRun(outputs, dir); });
  std::cout << std::fixed << std::setprecision(3) << "deformed " << o.mesh << " with " << springs.targets.rows()
            << " springs: " << (result.levels.back().converged ? "equilibrium" : "step limit reached") << " after "
            << result.steps << " steps, " << std::setprecision(2) << seconds << " s; farthest target "
            << std::setprecision(3) << result.maxDistancePercent << " % of the model's diameter ("
            << result.levels.back().level << " refinement(s), " << result.mesh.vertexCount() << " control vertices"
            << (result.toleranceMet ? ")" : "; above the tolerance)") << "\n"
            << "wrote " << (dir / kSurfaceFile).string() << ", control_mesh.obj, report.json\n";
  for (const std::string& warning : warnings) std::cerr << "warning: " << warning << '\n';
}

}  // namespace

void addDeformCommand(CLI::App& app) {
  auto o = std::make_shared<DeformArguments>();
  CLI::App* command = app.add_subcommand(
      "deform",
      "Model a surface by pulling on it: springs from points in space attach to the nearest points of the "
      "limit surface, and the surface moves under its dynamics to equilibrium.\n"
      "Writes DIR/surface.vtp, DIR/control_mesh.obj and DIR/report.json.");
  command->add_option("MESH", o->mesh, "Control mesh (.obj, .off or .ply), open or closed")->required();
  command->add_option("--springs", o->springs,
                      "Spring file: one spring per line, 'x y z' or 'x y z stiffness' (mm, N/mm)")
      ->required();
  command->add_option("--out", o->out, "Output directory (created if missing; its parent must exist)")->required();
  command->add_option("--stiffness", o->stiffness, "Stiffness of springs that do not give one, N/mm (up to 1e12)")
      ->default_val(o->stiffness)
      ->check(positiveNumber(kLargestSpringStiffness));
  command->add_flag("--fix-boundary", o->fixBoundary,
                    "Hold the boundary of an open mesh in place: its control vertices, and after refinement their new "
                    "boundary points");
  command
      ->add_option("--tolerance", o->deformation.tolerancePercent,
                   "Largest distance from a spring's target to the surface at which refinement (up to --max-level) "
                   "stops, in percent of the diameter of the smallest sphere enclosing the control mesh and the "
                   "targets")
      ->default_val(o->deformation.tolerancePercent)
      ->check(positiveNumber());
  command
      ->add_option("--refinement", o->refinement,
                   "local: a level's faces near the targets still farther than the tolerance are refined and their "
                   "new points move, while elsewhere the refined mesh keeps the coarser level's shape (the static "
                   "scheme; otherwise every face); global: every face, as the papers do")
      ->default_val("local")
      ->check(CLI::IsMember({"local", "global"}));
  command
      ->add_option("--rest-shape", o->restShape,
                   "initial: the surface's elasticity resists departing from the input mesh's shape, so only the "
                   "pulled region gives where springs or --fix-boundary hold the rest (else the surface moves as a "
                   "whole); none: it resists any stretch and bend, as the papers' model does, and a closed surface "
                   "pulled in one place shrinks elsewhere unless springs anchor it")
      ->default_val("initial")
      ->check(CLI::IsMember({"initial", "none"}));
  o->simulation.addOptions(*command, DeformationOptions::defaultSimulation());
  command->callback([o] { runDeform(*o); });
}

}  // namespace dynsub::app
