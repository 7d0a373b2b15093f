// dynsub deform: modeling by forces (TVCG §4.1, Fig. 6): springs from points in
// space to the nearest points of the limit surface pull it to a new equilibrium.
#include <filesystem>
#include <iomanip>
#include <iostream>

#include <CLI/CLI.hpp>

#include "CommandLine.h"
#include "Commands.h"
#include "EarlierRuns.h"
#include "dynsub/Error.h"
#include "dynsub/ForceModel.h"
#include "dynsub/MeshIO.h"
#include "dynsub/ModelOutputs.h"
#include "dynsub/SpringFile.h"

namespace dynsub::app {

namespace {

struct DeformOptions {
  std::string mesh;
  std::string springs;
  std::string out;
  double stiffness = 10.0;
  bool fixBoundary = false;
  SimulationArguments simulation;
};

void runDeform(DeformOptions o) {
  const ControlMesh mesh = readControlMesh(o.mesh);
  const SpringFile springs = readSpringFile(o.springs, o.stiffness);
  const std::filesystem::path dir(o.out);
  prepareOutputDirectory(dir);
  SimulationOptions options = o.simulation.apply(o.simulation.values);

  std::vector<int> fixed;
  if (o.fixBoundary) {
    const Topology& topology = mesh.topology();
    for (int v = 0; v < mesh.vertexCount(); ++v) {
      if (topology.isBoundaryVertex(v)) fixed.push_back(v);
    }
    if (fixed.empty()) throw Error(o.mesh, "--fix-boundary was given, but the mesh is closed");
  }
  SpringForceModel model(springs.targets, springs.stiffness, SpringForceModel::Attach::NearestAtLevelStart);
  ProgressLine line;
  const SimulationResult result = simulate(mesh, {&model}, fixed, options, nullptr, line.callback());
  line.finish();

  const Eigen::VectorXd& lengths = model.lengths();
  double seconds = 0.0;
  for (const LevelSummary& l : result.levels) seconds += l.seconds;

  Report report;
  report.set("input", o.mesh);
  report.set("springs_file", o.springs);
  report.set("springs", springs.targets.rows());
  report.set("fixed_control_vertices", fixed.size());
  report.set("control_vertices", result.mesh.vertexCount());
  report.set("levels", result.levels.back().level);
  report.set("iterations", result.steps);
  report.set("equilibrium", result.levels.back().converged);
  report.set("max_spring_length_mm", lengths.size() ? lengths.maxCoeff() : 0.0);
  report.set("mean_spring_length_mm", lengths.size() ? lengths.mean() : 0.0);
  report.set("seconds", seconds);
  std::vector<Report> levels;
  for (const LevelSummary& l : result.levels) levels.push_back(levelReport(l, -1, -1));
  report.set("per_level", levels);
  Report parameters = simulationReport(options);
  parameters.set("default_spring_stiffness", o.stiffness);
  parameters.set("fix_boundary", o.fixBoundary);
  report.set("parameters", parameters);

  writeModelOutputs(dir, result.mesh, outputSurface(result.mesh), report,
                    [&dir](OutputSet& outputs) { retireEarlierRun(outputs, dir); });
  std::cout << std::fixed << std::setprecision(3) << "deformed " << o.mesh << " with " << springs.targets.rows()
            << " springs: " << (result.levels.back().converged ? "equilibrium" : "step limit reached") << " after "
            << result.steps << " steps, " << std::setprecision(2) << seconds << " s; largest spring length "
            << std::setprecision(3) << (lengths.size() ? lengths.maxCoeff() : 0.0) << " mm\n"
            << "wrote " << (dir / kSurfaceFile).string() << ", control_mesh.obj, report.json\n";
}

}  // namespace

void addDeformCommand(CLI::App& app) {
  auto o = std::make_shared<DeformOptions>();
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
  command->add_option("--stiffness", o->stiffness, "Stiffness of springs that do not give one, N/mm")
      ->default_val(o->stiffness)
      ->check(positiveNumber());
  command->add_flag("--fix-boundary", o->fixBoundary, "Hold the boundary control vertices of an open mesh in place");
  SimulationOptions defaults;
  defaults.maxLevel = 0;
  // Springs held at their attachments are linear: the static scheme's first
  // Newton step is the exact equilibrium (residual 1e-14 where first-order
  // time steps stop at 1e-2 after ~300 steps; Documentation/Performance.md).
  defaults.integrator.scheme = IntegrationScheme::Static;
  o->simulation.addOptions(*command, defaults);
  command->callback([o] { runDeform(*o); });
}

}  // namespace dynsub::app
