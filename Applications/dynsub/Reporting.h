#pragma once
// What the commands that run a simulation share: the physics and solver
// options, a progress line on a terminal, and writing a set of outputs into a
// directory all together or not at all.
#include <filesystem>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "dynsub/Simulation.h"
#include "dynsub/SurfaceWriter.h"

namespace CLI {
class App;
}

namespace dynsub {
class AtomicOutput;
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

nlohmann::ordered_json simulationJson(const SimulationOptions& options);
nlohmann::ordered_json levelJson(const LevelSummary& level, double maxErrorPercent, double rmsErrorPercent);

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

// Throws dynsub::Error unless `dir` is a directory or can be created (its parent exists).
void prepareOutputDirectory(const std::filesystem::path& dir);

// Files in one directory that appear together: each is written to a temporary
// file, and commit() renames them all; before that nothing is visible (a
// directory this created is removed again if commit() is never reached). A
// set holds an exclusive lock (flock) on its directory for its lifetime, so
// the sets of two runs writing there at once never interleave.
class OutputSet {
 public:
  explicit OutputSet(std::filesystem::path dir);
  ~OutputSet();
  OutputSet(const OutputSet&) = delete;
  OutputSet& operator=(const OutputSet&) = delete;
  // The temporary path to write `name` to.
  std::string add(const std::string& name);
  void commit();

 private:
  std::filesystem::path dir_;
  bool created_ = false;
  bool committed_ = false;
  int lock_ = -1;  // the directory, opened to hold its lock
  std::vector<std::unique_ptr<AtomicOutput>> outputs_;
};

void writeJson(const nlohmann::ordered_json& json, const std::string& path);

// The limit surface as the programs write it: 8 x 8 squares per element.
// Throws dynsub::Error if the control points are not finite.
TriangleSurface outputSurface(const ControlMesh& mesh);

// The outputs of a simulation, all or none: DIR/surface.vtp (the limit
// surface, 8 x 8 squares per element), DIR/control_mesh.obj, DIR/report.json.
// Throws dynsub::Error if the control points are not finite.
// `extra` may add further files to the same set (e.g. a labelmap);
// `surfaceScalars` are point data of surface.vtp (one value per point of that
// tessellation, as tessellate(LimitSurface(mesh), mesh.points(), 8) orders them);
// `space` ("LPS" for surfaces in an image's physical space) is recorded in
// surface.vtp for 3D Slicer (SurfaceWriter.h).
void writeModelOutputs(const std::filesystem::path& dir, const ControlMesh& mesh,
                       const nlohmann::ordered_json& report,
                       const std::function<void(OutputSet&)>& extra = nullptr,
                       const std::vector<PointScalars>& surfaceScalars = {}, const std::string& space = "");

}  // namespace dynsub::app
