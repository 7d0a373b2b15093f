#include "dynsub/ModelOutputs.h"

#include <iomanip>
#include <sstream>
#include <string>

#include "dynsub/Coordinates.h"
#include "dynsub/Error.h"
#include "dynsub/LimitSurface.h"
#include "dynsub/MeshCheck.h"
#include "dynsub/MeshIO.h"
#include "dynsub/ParallelFor.h"
#include "dynsub/SelfIntersection.h"

namespace dynsub {

Report simulationReport(const SimulationOptions& o) {
  Report r;
  r.set("max_level", o.maxLevel);
  r.set("scheme", toString(o.integrator.scheme));
  r.set("solver", toString(o.integrator.solver));
  r.set("time_step_s", o.integrator.timeStep);
  Report material;
  material.set("mass", o.material.mass);
  material.set("damping", o.material.damping);
  material.set("tension_u", o.material.tensionU);
  material.set("tension_v", o.material.tensionV);
  material.set("rigidity_uu", o.material.rigidityUU);
  material.set("rigidity_uv", o.material.rigidityUV);
  material.set("rigidity_vv", o.material.rigidityVV);
  r.set("material", material);
  r.set("elasticity_per_level", o.elasticityPerLevel);
  r.set("relaxations", o.relaxations);
  r.set("plate_levels", o.assembly.plateLevels);
  Report equilibrium;
  equilibrium.set("energy_tolerance", o.equilibrium.energyTolerance);
  equilibrium.set("motion_tolerance", o.equilibrium.motionTolerance);
  equilibrium.set("coarse_level_factor", o.equilibrium.coarseLevelFactor);
  equilibrium.set("window", o.equilibrium.window);
  equilibrium.set("max_steps", o.equilibrium.maxSteps);
  r.set("equilibrium", equilibrium);
  return r;
}

Report levelReport(const LevelSummary& l, double maxErrorPercent, double rmsErrorPercent) {
  Report r;
  r.set("level", l.level);
  r.set("control_vertices", l.controlVertices);
  r.set("free_control_points", l.freeControlPoints);
  // How the level came from the one before: what was done, which can be
  // global where local was asked for (Simulation.h).
  if (l.level > 0) r.set("refinement", l.localRefinement ? "local" : "global");
  r.set("elasticity", l.elasticity);
  r.set("iterations", l.steps);
  r.set("equilibrium", l.converged && !l.met);
  // coarse: ended at looser tolerances; met: ended where the fit met its
  // tolerance, before either rule (LevelSummary).
  r.set("equilibrium_rule", l.met ? "met" : l.coarse ? "coarse" : "full");
  r.set("time_step_s", l.timeStep);
  r.set("divergences", l.divergences);
  r.set("energy", l.energy);
  if (maxErrorPercent >= 0) {
    r.set("max_error_percent", maxErrorPercent);
    r.set("rms_error_percent", rmsErrorPercent);
  }
  r.set("stabilizer_updates", l.stabilizerUpdates);
  r.set("equilibrium_residual", l.residual);
  r.set("seconds", l.seconds);
  return r;
}

Report selfIntersectionReport(const TriangleSurface& surface, const std::string& space,
                              std::vector<std::string>& warnings) {
  const SelfIntersection found = findSelfIntersections(surface);
  Report r;
  r.set("triangle_pairs", found.trianglePairs);
  r.set("area_percent", found.areaPercent);
  if (found.trianglePairs == 0) return r;
  r.set("bounds_mm", std::vector<Vector3>{found.boundsMin, found.boundsMax});
  const auto point = [](const Vector3& p) {
    std::ostringstream text;
    text << std::fixed << std::setprecision(1) << "(" << p.x() << ", " << p.y() << ", " << p.z() << ")";
    return text.str();
  };
  std::ostringstream text;
  text << "the surface passes through itself: " << found.trianglePairs << " pairs of its triangles cross, over "
       << std::fixed << std::setprecision(2) << found.areaPercent << " % of its area, between "
       << point(found.boundsMin) << " and " << point(found.boundsMax) << " mm" << (space.empty() ? "" : " ") << space
       << ": there it bounds no solid, and tools that need one (a mesh boolean, a thickness measure, a mask "
          "filled by the even-odd rule) go wrong; look at the result in that box";
  warnings.push_back(text.str());
  return r;
}

TriangleSurface outputSurface(const ControlMesh& mesh) { return outputSurface(mesh, LimitSurface(mesh)); }

TriangleSurface outputSurface(const ControlMesh& mesh, const LimitSurface& surface) {
  if (!mesh.points().allFinite()) throw Error("internal: the control points are not finite; nothing was written");
  if (surface.controlVertexCount() != mesh.vertexCount())
    throw Error("internal: the limit surface is not the control mesh's");
  return tessellate(surface, mesh.points(), outputSegments(surface));
}

void writeModelOutputs(const std::filesystem::path& dir, const ControlMesh& mesh, const TriangleSurface& surface,
                       const Report& report, const std::function<void(OutputSet&)>& extra,
                       const std::vector<PointScalars>& surfaceScalars, const std::string& space) {
  // A model the readers refuse is not written as a result: one that ran
  // off (a point past the largest coordinate) diverged; one with a face of
  // no area shrank to a point or a line.
  for (Eigen::Index v = 0; v < mesh.points().rows(); ++v) {
    const std::string beyond = beyondLargestCoordinate(mesh.points().row(v).transpose());
    if (!beyond.empty())
      throw Error("the model diverged: control vertex " + std::to_string(v) + " " + beyond +
                  " (lower the time step or the stiffest force; nothing was written)");
  }
  try {
    checkPolygonMesh(mesh.points(), mesh.faces(), "the resulting control mesh");
  } catch (const Error& error) {
    throw Error(std::string("the model collapsed: ") + error.what() +
                " (tension draws a surface in where no force holds it out: add springs or points, or lower --tension)");
  }
  OutputSet outputs(dir);
  // The model's files (surface.vtp, control_mesh.obj, report.json) are
  // written on a second thread while `extra` (a segmentation's labelmap, the
  // figures) writes on this one: compressing the surface and the labelmap
  // each take a sizeable share of a segmentation command. Only this thread
  // adds outputs to the set. An error writing the model's files is reported
  // first, as if they were written first, and nothing is committed unless
  // all went.
  const std::string surfacePath = outputs.add(kSurfaceFile), meshPath = outputs.add(kControlMeshFile),
                    reportPath = outputs.add(kReportFile);
  alongside(
      [&] {
        writeTriangleSurface(surface, surfacePath, surfaceScalars, space);
        writeObj(mesh, meshPath);
        report.write(reportPath);
      },
      [&] {
        if (extra) extra(outputs);
      });
  outputs.commit();
}

}  // namespace dynsub
