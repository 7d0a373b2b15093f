#include <iostream>

#include <CLI/CLI.hpp>

#include "Commands.h"
#include "dynsub/MeshIO.h"
#include "dynsub/StandardMeshes.h"

namespace dynsub::app {

void addMeshCommand(CLI::App& app) {
  struct MeshOptions {
    std::string name;
    std::string out;
  };
  auto options = std::make_shared<MeshOptions>();
  CLI::App* command = app.add_subcommand(
      "mesh",
      "Write one of the papers' initial control meshes as OBJ: cube (98 vertices, 96 quads, 8 "
      "extraordinary vertices of valence 3), torus (32 vertices, 32 quads) or sheet (81 vertices, "
      "64 quads, open).");
  command->add_option("NAME", options->name, "cube, torus or sheet")
      ->required()
      ->check(CLI::IsMember(standardMeshNames()));
  command->add_option("--out", options->out, "Output file (.obj)")->required();
  command->callback([options] {
    const ControlMesh mesh = makeStandardMesh(options->name);
    writeObj(mesh, options->out);
    std::cout << "wrote " << options->out << ": " << mesh.vertexCount() << " vertices, " << mesh.faceCount()
              << " faces\n";
  });
}

}  // namespace dynsub::app
