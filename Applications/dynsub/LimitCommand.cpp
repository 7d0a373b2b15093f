#include <iostream>

#include <CLI/CLI.hpp>

#include "CommandLine.h"
#include "Commands.h"
#include "dynsub/Error.h"
#include "dynsub/FileNames.h"
#include "dynsub/LimitSurface.h"
#include "dynsub/Memory.h"
#include "dynsub/MeshIO.h"
#include "dynsub/SurfaceWriter.h"
#include "dynsub/Tessellation.h"

namespace dynsub::app {

namespace {

struct LimitOptions {
  std::string mesh;
  std::string out;
  int samplesPerFace = 8;
};

void runLimit(const LimitOptions& options) {
  requireTriangleSurfaceTarget(options.out);
  requireNotInput(options.out, options.mesh);
  const ControlMesh mesh = readControlMesh(options.mesh);
  const LimitSurface surface(mesh);
  // Refused before any work, the memory first (its finest size is the
  // smaller on any machine of less than about 200 GB): a surface of billions
  // of triangles otherwise runs for minutes before the allocator fails.
  requireMemoryForSize(
      options.samplesPerFace, 1,
      [&](int n) {
        const TessellationSize size = tessellationSize(surface, n);
        return static_cast<long double>(size.bytes + surfaceWriterBytes(options.out, size.samples, size.triangles));
      },
      options.mesh, std::to_string(options.samplesPerFace) + " samples per face (the surface and its writing)",
      "--samples-per-face");
  // The option's value is at fault: a usage error.
  if (const std::string tooFine = tessellationTooFine(surface, options.samplesPerFace); !tooFine.empty())
    throw UsageError(options.mesh, tooFine);
  const TriangleSurface triangles = tessellate(surface, mesh.points(), options.samplesPerFace);
  writeTriangleSurface(triangles, options.out);
  int special = 0;
  for (int e = 0; e < surface.elementCount(); ++e) special += surface.elementType(e) == ElementType::Special;
  const int pieces = mesh.pieceCount();
  std::cout << "control mesh: " << mesh.vertexCount() << " vertices, " << mesh.faceCount() << " faces, "
            << (pieces > 1 ? std::to_string(pieces) + " pieces, " : "") << "genus " << mesh.genus()
            << (mesh.isClosed() ? ", closed" : ", with boundary") << '\n'
            << "limit surface: " << surface.elementCount() << " elements (" << surface.elementCount() - special
            << " normal, " << special << " special) after " << surface.isolationLevels()
            << " isolating subdivision(s)\n"
            << "wrote " << options.out << ": " << triangles.points.rows() << " points, " << triangles.triangles.size()
            << " triangles\n";
}

}  // namespace

void addLimitCommand(CLI::App& app) {
  auto options = std::make_shared<LimitOptions>();
  CLI::App* command = app.add_subcommand(
      "limit",
      "Evaluate the exact limit surface of a control mesh and write it as a triangle mesh.\n"
      "Each element (a face of the control mesh, or of its refinement when the mesh has non-quads or "
      "adjacent extraordinary vertices) is sampled on an N x N grid of parameter squares.\n"
      "Output formats by extension: .vtp (with point normals and the cell data ElementType: 0 normal, "
      "1 special element, and Element), .obj, .ply, .stl.");
  command->add_option("MESH", options->mesh, "Control mesh (.obj, .off or .ply), closed or with boundaries")
      ->required();
  command->add_option("--out", options->out, "Output surface file (.vtp, .vtk, .obj, .ply or .stl)")->required();
  command
      ->add_option("--samples-per-face", options->samplesPerFace,
                   "N: parameter squares along each side of an element (1 to 1024)")
      ->default_val(8)
      ->check(numberBetween(1, 1024, true));
  command->callback([options] { runLimit(*options); });
}

}  // namespace dynsub::app
