#pragma once
// What every command that moves a model writes (`fit`, `deform`, `segment`,
// the 3D Slicer module): the limit surface, the control mesh and report.json,
// all together or none (OutputSet.h), and the parts of report.json they share.
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "dynsub/OutputSet.h"
#include "dynsub/Report.h"
#include "dynsub/Simulation.h"
#include "dynsub/SurfaceWriter.h"

namespace dynsub {

// report.json's "parameters": the material, the scheme, the levels and the equilibrium rule.
Report simulationReport(const SimulationOptions& options);
// One entry of report.json's "per_level"; the fit errors are left out when negative.
Report levelReport(const LevelSummary& level, double maxErrorPercent, double rmsErrorPercent);

// report.json's "self_intersection" for the surface a command writes: how
// many pairs of its triangles cross (SelfIntersection.h), their share of its
// area and their bounding box. Where it crosses itself, a warning that names
// the box is added to `warnings`; `space` names the coordinates ("LPS", or ""
// for the input's own).
Report selfIntersectionReport(const TriangleSurface& surface, const std::string& space,
                              std::vector<std::string>& warnings);

// The limit surface as the programs write it (outputSegments, Tessellation.h).
// Throws dynsub::Error if the control points are not finite.
TriangleSurface outputSurface(const ControlMesh& mesh);
// The same from `mesh`'s limit surface built already (SimulationResult::surface).
TriangleSurface outputSurface(const ControlMesh& mesh, const LimitSurface& surface);

// The files writeModelOutputs writes in its directory.
constexpr char kSurfaceFile[] = "surface.vtp";
constexpr char kControlMeshFile[] = "control_mesh.obj";
constexpr char kReportFile[] = "report.json";

// DIR/surface.vtp (`surface`, from outputSurface), DIR/control_mesh.obj and
// DIR/report.json, all or none; none, with an error, when the control mesh
// fails MeshCheck.h (the model collapsed). `extra` may add further files to the same set
// (e.g. a labelmap); `surfaceScalars` are point data of surface.vtp (one value
// per point of `surface`); `space` ("LPS" for surfaces in an image's physical
// space) is recorded in surface.vtp for 3D Slicer (SurfaceWriter.h).
void writeModelOutputs(const std::filesystem::path& dir, const ControlMesh& mesh, const TriangleSurface& surface,
                       const Report& report, const std::function<void(OutputSet&)>& extra = nullptr,
                       const std::vector<PointScalars>& surfaceScalars = {}, const std::string& space = "");

}  // namespace dynsub
