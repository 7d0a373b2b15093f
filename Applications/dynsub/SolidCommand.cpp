// dynsub solid: Catmull-Clark subdivision solids (Lattice.h, SolidSubdivision.h).
#include <iostream>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "Commands.h"
#include "dynsub/Error.h"
#include "dynsub/LatticeIO.h"
#include "dynsub/SolidSubdivision.h"

namespace dynsub::app {

namespace {

// The paper's Table 1 models DynSub rebuilds (cell size 1 mm).
Lattice standardLattice(const std::string& name) {
  if (name == "cube3") return regularLattice(2, 2, 2);
  if (name == "cube4") return regularLattice(3, 3, 3);
  // The 3 x 3 x 3 cube without its centre cell and the 6 cells at its face
  // centres: a hole through it along each axis.
  if (name == "cube-holes") return regularLattice(3, 3, 3, 1.0, {13, 4, 22, 10, 16, 12, 14});
  throw Error("unknown lattice '" + name + "' (expected cube3, cube4 or cube-holes)");
}

struct SolidOptions {
  std::string lattice, name, out;
  int level = 0;
};

}  // namespace

void addSolidCommand(CLI::App& app) {
  auto o = std::make_shared<SolidOptions>();
  CLI::App* solid = app.add_subcommand("solid", "Catmull-Clark subdivision solids: control lattices of cells");
  solid->require_subcommand(1);

  CLI::App* stats = solid->add_subcommand(
      "stats", "Print the counts of points, edges, faces and cells after L subdivisions, as JSON");
  stats->add_option("LATTICE", o->lattice, "Control lattice (.lattice)")->required();
  stats->add_option("--level", o->level, "Subdivisions")->default_val(0)->check(CLI::Range(0, 6));
  stats->callback([o] {
    const Lattice lattice = subdivideSolid(readLattice(o->lattice), o->level).lattice;
    nlohmann::ordered_json counts = {{"points", lattice.pointCount()},
                                     {"edges", lattice.edgeCount()},
                                     {"faces", lattice.faceCount()},
                                     {"cells", lattice.cellCount()}};
    std::cout << counts.dump() << '\n';
  });

  CLI::App* subdivide = solid->add_subcommand(
      "subdivide", "Subdivide a lattice L times and write it (.lattice, or .vtu for ParaView)");
  subdivide->add_option("LATTICE", o->lattice, "Control lattice (.lattice)")->required();
  subdivide->add_option("--level", o->level, "Subdivisions")->default_val(1)->check(CLI::Range(0, 6));
  subdivide->add_option("--out", o->out, "Output file (.lattice or .vtu)")->required();
  subdivide->callback([o] {
    const Lattice lattice = subdivideSolid(readLattice(o->lattice), o->level).lattice;
    writeLattice(lattice, o->out);
    std::cout << "wrote " << o->out << ": " << lattice.pointCount() << " points, " << lattice.cellCount()
              << " cells\n";
  });

  CLI::App* make = solid->add_subcommand("make", "Write one of the paper's Table 1 lattices");
  make->add_option("NAME", o->name, "cube3 (Cube 3^3), cube4 (Cube 4^3) or cube-holes (Cube w/ holes)")
      ->required()
      ->check(CLI::IsMember({"cube3", "cube4", "cube-holes"}));
  make->add_option("--out", o->out, "Output file (.lattice or .vtu)")->required();
  make->callback([o] {
    const Lattice lattice = standardLattice(o->name);
    writeLattice(lattice, o->out);
    std::cout << "wrote " << o->out << ": " << lattice.pointCount() << " points, " << lattice.edgeCount()
              << " edges, " << lattice.faceCount() << " faces, " << lattice.cellCount() << " cells\n";
  });
}

}  // namespace dynsub::app
