#include "Reporting.h"

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <iostream>

#include <CLI/CLI.hpp>

#include "dynsub/AtomicOutput.h"
#include "dynsub/Error.h"
#include "dynsub/TemporaryFileGuard.h"
#include "dynsub/LimitSurface.h"
#include "dynsub/MeshIO.h"
#include "dynsub/SurfaceWriter.h"
#include "dynsub/Tessellation.h"

namespace dynsub::app {

void SimulationArguments::addOptions(CLI::App& command, const SimulationOptions& defaults) {
  values = defaults;
  scheme = toString(defaults.integrator.scheme);
  solver = toString(defaults.integrator.solver);
  command.add_option("--max-level", values.maxLevel, "Global refinements allowed (0-6)")
      ->default_val(defaults.maxLevel)
      ->check(CLI::Range(0, 6));
  command.add_option("--scheme", scheme,
                     "How the equilibrium is reached: static (Newton steps on K p = f_p), or time integration, "
                     "first-order (massless, TVCG eq. 32) or second-order (eq. 31)")
      ->default_val(scheme)
      ->check(CLI::IsMember({"static", "first-order", "second-order"}));
  command.add_option("--solver", solver,
                     "Linear solver per step: cholesky (factored once per level), cg, or pcg (incomplete Cholesky)")
      ->default_val(solver)
      ->check(CLI::IsMember({"cholesky", "cg", "pcg"}));
  command.add_option("--time-step", values.integrator.timeStep, "Time step, s (halved automatically on divergence)")
      ->default_val(defaults.integrator.timeStep)
      ->check(CLI::PositiveNumber);
  command.add_option("--max-steps", values.equilibrium.maxSteps, "Step limit per level")
      ->default_val(defaults.equilibrium.maxSteps)
      ->check(CLI::Range(1, 1000000));
  command.add_option("--mass", values.material.mass, "Mass density mu, kg per unit parametric area")
      ->default_val(defaults.material.mass)
      ->check(CLI::NonNegativeNumber);
  command.add_option("--damping", values.material.damping, "Damping density gamma, kg/s per unit parametric area")
      ->default_val(defaults.material.damping)
      ->check(CLI::NonNegativeNumber);
  command.add_option("--tension", values.material.tensionU,
                     "Tension alpha11 = alpha22, N/mm per unit parametric area (membrane: resists stretching)")
      ->default_val(defaults.material.tensionU)
      ->check(CLI::NonNegativeNumber);
  command.add_option("--rigidity", values.material.rigidityUU,
                     "Rigidity beta11 = beta22 = beta12/2, N/mm per unit parametric area (thin plate: resists bending)")
      ->default_val(defaults.material.rigidityUU)
      ->check(CLI::NonNegativeNumber);
}

SimulationOptions SimulationArguments::apply(SimulationOptions base) const {
  base.maxLevel = values.maxLevel;
  base.integrator.scheme = parseIntegrationScheme(scheme);
  base.integrator.solver = parseLinearSolver(solver);
  base.integrator.timeStep = values.integrator.timeStep;
  base.equilibrium.maxSteps = values.equilibrium.maxSteps;
  base.material.mass = values.material.mass;
  base.material.damping = values.material.damping;
  base.material.tensionU = base.material.tensionV = values.material.tensionU;
  base.material.rigidityUU = base.material.rigidityVV = values.material.rigidityUU;
  base.material.rigidityUV = 2.0 * values.material.rigidityUU;
  checkSimulationOptions(base);
  return base;
}

nlohmann::ordered_json simulationJson(const SimulationOptions& o) {
  nlohmann::ordered_json j;
  j["max_level"] = o.maxLevel;
  j["scheme"] = toString(o.integrator.scheme);
  j["solver"] = toString(o.integrator.solver);
  j["time_step_s"] = o.integrator.timeStep;
  j["material"] = {{"mass", o.material.mass},           {"damping", o.material.damping},
                   {"tension_u", o.material.tensionU},  {"tension_v", o.material.tensionV},
                   {"rigidity_uu", o.material.rigidityUU}, {"rigidity_uv", o.material.rigidityUV},
                   {"rigidity_vv", o.material.rigidityVV}};
  j["elasticity_per_level"] = o.elasticityPerLevel;
  j["plate_levels"] = o.assembly.plateLevels;
  j["equilibrium"] = {{"energy_tolerance", o.equilibrium.energyTolerance},
                      {"motion_tolerance", o.equilibrium.motionTolerance},
                      {"coarse_level_factor", o.equilibrium.coarseLevelFactor},
                      {"window", o.equilibrium.window},
                      {"max_steps", o.equilibrium.maxSteps}};
  return j;
}

nlohmann::ordered_json levelJson(const LevelSummary& l, double maxErrorPercent, double rmsErrorPercent) {
  nlohmann::ordered_json j;
  j["level"] = l.level;
  j["control_vertices"] = l.controlVertices;
  j["iterations"] = l.steps;
  j["equilibrium"] = l.converged;
  j["equilibrium_rule"] = l.coarse ? "coarse" : "full";  // coarse: a refined level, ended at looser tolerances
  j["time_step_s"] = l.timeStep;
  j["energy"] = l.energy;
  if (maxErrorPercent >= 0) {
    j["max_error_percent"] = maxErrorPercent;
    j["rms_error_percent"] = rmsErrorPercent;
  }
  j["stabilizer_updates"] = l.stabilizerUpdates;
  j["equilibrium_residual"] = l.residual;
  j["seconds"] = l.seconds;
  return j;
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

void prepareOutputDirectory(const std::filesystem::path& dir) {
  std::error_code error;
  if (std::filesystem::exists(dir, error)) {
    if (!std::filesystem::is_directory(dir, error)) throw Error(dir.string(), "exists and is not a directory");
    requireWritableDirectoryFor((dir / "report.json").string());
    return;
  }
  const std::filesystem::path parent = dir.has_parent_path() ? dir.parent_path() : std::filesystem::path(".");
  if (!std::filesystem::is_directory(parent, error)) {
    throw Error(dir.string(), "cannot be created: " + parent.string() + " does not exist");
  }
  requireWritableDirectoryFor(dir.string());
}

OutputSet::OutputSet(std::filesystem::path dir) : dir_(std::move(dir)) {
  std::error_code error;
  if (!std::filesystem::exists(dir_, error)) {
    if (!std::filesystem::create_directory(dir_, error)) throw Error(dir_.string(), "cannot be created: " + error.message());
    created_ = true;
    temporaryfiles::createdDirectory(std::filesystem::absolute(dir_).string());
  }
  // Two runs writing to one directory at once take turns: each holds a lock
  // on the directory from its first file to its commit, so their files never
  // interleave (the last run's set is the one that stays whole).
  lock_ = ::open(dir_.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (lock_ < 0) throw Error(dir_.string(), "cannot be opened: " + std::string(std::strerror(errno)));
  if (::flock(lock_, LOCK_EX | LOCK_NB) != 0) {
    std::cerr << "dynsub: waiting for another run writing to " << dir_.string() << '\n';
    while (::flock(lock_, LOCK_EX) != 0 && errno == EINTR) {
    }
  }
}

OutputSet::~OutputSet() {
  outputs_.clear();  // removes uncommitted temporary files
  if (created_ && !committed_) {
    std::error_code error;
    std::filesystem::remove(dir_, error);
  }
  if (created_) temporaryfiles::finishedDirectory(std::filesystem::absolute(dir_).string());
  if (lock_ >= 0) ::close(lock_);  // releases the lock
}

std::string OutputSet::add(const std::string& name) {
  outputs_.push_back(std::make_unique<AtomicOutput>((dir_ / name).string()));
  return outputs_.back()->temporaryPath();
}

void OutputSet::commit() {
  for (auto& output : outputs_) output->commit();
  committed_ = true;
}

void writeJson(const nlohmann::ordered_json& json, const std::string& path) {
  std::ofstream out(path);
  out << json.dump(2) << '\n';
  out.close();
  if (!out) throw writeFailure(path);
}

TriangleSurface outputSurface(const ControlMesh& mesh) {
  const Matrix3X control = mesh.points();
  if (!control.allFinite()) throw Error("internal: the control points are not finite; nothing was written");
  return tessellate(LimitSurface(mesh), control, 8);
}

void writeModelOutputs(const std::filesystem::path& dir, const ControlMesh& mesh,
                       const nlohmann::ordered_json& report, const std::function<void(OutputSet&)>& extra,
                       const std::vector<PointScalars>& surfaceScalars, const std::string& space) {
  const TriangleSurface triangles = outputSurface(mesh);
  OutputSet outputs(dir);
  writeTriangleSurface(triangles, outputs.add("surface.vtp"), surfaceScalars, space);
  writeObj(mesh, outputs.add("control_mesh.obj"));
  writeJson(report, outputs.add("report.json"));
  if (extra) extra(outputs);
  outputs.commit();
}

}  // namespace dynsub::app
