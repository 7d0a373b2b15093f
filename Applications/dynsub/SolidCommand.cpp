// dynsub solid: Catmull-Clark subdivision solids (Lattice.h, SolidSubdivision.h)
// and sculpting them (Sculpting.h, SculptScript.h, Sculptor.h).
#include <chrono>
#include <cmath>
#include <iostream>

#include <CLI/CLI.hpp>

#include "CommandLine.h"
#include "Commands.h"
#include "EarlierRuns.h"
#include "dynsub/Error.h"
#include "dynsub/FileNames.h"
#include "dynsub/LatticeIO.h"
#include "dynsub/Memory.h"
#include "dynsub/ModelOutputs.h"
#include "dynsub/OutputSet.h"
#include "dynsub/Report.h"
#include "dynsub/SculptScript.h"
#include "dynsub/FigureInputs.h"
#include "dynsub/Sculptor.h"
#include "dynsub/SolidView.h"
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

struct SculptOptions {
  std::string lattice, script, out = "sculpted", scheme = "semi-implicit";
  SculptSettings settings;
  bool figure = true;
};

Report countsReport(const LatticeCounts& counts) {
  Report r;
  r.set("points", counts.points);
  r.set("edges", counts.edges);
  r.set("faces", counts.faces);
  r.set("cells", counts.cells);
  return r;
}

Report countsReport(const Lattice& lattice) {
  return countsReport(LatticeCounts{static_cast<std::uint64_t>(lattice.pointCount()),
                                    static_cast<std::uint64_t>(lattice.edgeCount()),
                                    static_cast<std::uint64_t>(lattice.faceCount()),
                                    static_cast<std::uint64_t>(lattice.cellCount())});
}

// DIR/sculpted.lattice (the control lattice, to sculpt on later),
// DIR/sculpted.vtu (the subdivided solid where the mass points are),
// DIR/sculpted.png (SolidView's figure, with a display) and DIR/report.json,
// all together or none; what an earlier run wrote there and this one does
// not goes (EarlierRuns.h). Returns what was written.
std::string writeSculpture(const std::filesystem::path& dir, const Sculpture& sculpture, const SculptOptions& o,
                           Report report) {
  prepareOutputDirectory(dir);
  OutputSet outputs(dir);
  retireEarlierRun(outputs, dir);
  const Lattice control = sculpture.control();
  writeLattice(control, outputs.add(kSculptedLattice));
  Lattice solid = sculpture.model().dataLattice();
  solid.setPoints(sculpture.model().dataPoints());
  writeLattice(solid, outputs.add(kSculptedSolid));
  std::string figure;
  std::string why;
  if (o.figure && figureDisplay(&why)) {
    writeSculptureFigure(sculpture, outputs.add(kSculptedFigure));
    figure = std::string(", ") + kSculptedFigure;
  } else if (o.figure) {
    std::cerr << "warning: no figure written: " << why << '\n';
  }
  const SolidMaterial& m = sculpture.settings().material;
  report.set("level", sculpture.settings().levels);
  report.set("time_step_s", sculpture.settings().timeStep);
  report.set("scheme", o.scheme);
  Report material;
  material.set("mass", m.mass);
  material.set("damping_n_s_per_mm", m.damping);
  material.set("spring_stiffness_n_per_mm", m.springStiffness);
  material.set("virtual_stiffness_n_per_mm", m.virtualStiffness);
  material.set("rope_stiffness_n_per_mm", sculpture.settings().ropeStiffness);
  report.set("material", material);
  report.set("steps", sculpture.steps());
  report.set("simulated_seconds", sculpture.steps() * sculpture.settings().timeStep);
  report.set("control", countsReport(control));
  report.set("fixed_control_points", sculpture.model().fixedPoints().size());
  report.set("solid", countsReport(solid));
  report.set("kinetic_energy_n_mm", sculpture.model().kineticEnergy());
  report.set("spring_energy_n_mm", sculpture.model().springEnergy());
  report.write(outputs.add(kReportFile));
  outputs.commit();
  return std::string("saved ") + kSculptedLattice + ", " + kSculptedSolid + figure + ", " + kReportFile + " in " +
         dir.string();
}

void runSculpt(const SculptOptions& options) {
  SculptOptions o = options;
  o.settings.scheme = o.scheme == "explicit" ? SolidScheme::PaperExplicit : SolidScheme::SemiImplicit;
  const Lattice lattice = readLattice(o.lattice);
  // Saved from the window or at the script's end, the sculpture would
  // replace an input of the same name in --out. An --out that cannot be a
  // directory is said before a script runs (the window says it when s saves).
  requireInputsOutsideRun(o.out, {o.lattice, o.script});
  if (!o.script.empty()) prepareOutputDirectory(o.out);
  Report report;
  report.set("lattice", o.lattice);
  if (o.script.empty()) {
    // The window: s saves to --out.
    std::cout << "dynsub solid sculpt: press h in the window for the mouse and key bindings; s saves to " << o.out
              << '\n';
    Sculptor sculptor(lattice, o.settings, [o, report](const Sculpture& s) {
      return writeSculpture(o.out, s, o, report);
    });
    sculptor.run();
    return;
  }
  // The whole script is checked before the solid moves, and nothing is
  // written unless every action ran.
  const std::vector<SculptAction> actions = readSculptScript(o.script);
  Sculpture sculpture(lattice, o.settings);
  const auto start = std::chrono::steady_clock::now();
  runSculptScript(actions, sculpture, o.script, [&](const SculptAction& action) {
    std::cout << "line " << action.line << ": " << action.text << "  (t = " << sculpture.steps() * o.settings.timeStep
              << " s, " << sculpture.rest().cellCount() << " cells)\n";
  });
  report.set("script", o.script);
  report.set("actions", actions.size());
  report.set("seconds", std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
  std::cout << writeSculpture(o.out, sculpture, o, report) << '\n';
}

}  // namespace

void addSolidCommand(CLI::App& app) {
  auto o = std::make_shared<SolidOptions>();
  CLI::App* solid = app.add_subcommand("solid", "Catmull-Clark subdivision solids: control lattices of cells");
  solid->require_subcommand(1);

  CLI::App* stats = solid->add_subcommand(
      "stats", "Print the counts of points, edges, faces and cells after L subdivisions, as JSON");
  // Its own options: a default given to a variable another subcommand shares
  // would be overwritten by that subcommand's default.
  auto statsOptions = std::make_shared<SolidOptions>();
  stats->add_option("LATTICE", statsOptions->lattice, "Control lattice (.lattice)")->required();
  stats->add_option("--level", statsOptions->level, "Subdivisions")->default_val(0)->check(numberBetween(0, 6, true));
  stats->callback([statsOptions] {
    std::cout << countsReport(refinedCounts(readLattice(statsOptions->lattice), statsOptions->level)).text(-1);
  });

  CLI::App* subdivide = solid->add_subcommand(
      "subdivide", "Subdivide a lattice L times and write it (.lattice, or .vtu for ParaView)");
  subdivide->add_option("LATTICE", o->lattice, "Control lattice (.lattice)")->required();
  subdivide->add_option("--level", o->level, "Subdivisions")->default_val(1)->check(numberBetween(0, 6, true));
  subdivide->add_option("--out", o->out, "Output file (.lattice or .vtu)")->required();
  subdivide->callback([o] {
    requireLatticeTarget(o->out);
    requireNotInput(o->out, o->lattice);
    const Lattice control = readLattice(o->lattice);
    // A refined cell takes up to 3.4 KiB at its peak (`solid subdivide` of
    // the three Table 1 lattices and of prisms and pyramids at levels 4 and
    // 5: 2.75-3.4 KiB), and the cells grow eightfold a level.
    requireMemoryForSize(
        o->level, 0, [&](int level) { return 3.5L * 1024 * refinedCounts(control, level).cells; }, o->lattice,
        std::to_string(o->level) + " levels", "--level");
    const Lattice lattice = subdivideSolid(control, o->level).lattice;
    writeLattice(lattice, o->out);
    std::cout << "wrote " << o->out << ": " << lattice.pointCount() << " points, " << lattice.cellCount()
              << " cells\n";
  });

  auto so = std::make_shared<SculptOptions>();
  CLI::App* sculpt = solid->add_subcommand(
      "sculpt",
      "Sculpt a lattice as virtual clay: an interactive window (rope: Ctrl + drag; select a face: Shift + click; "
      "e extrude, d delete its cell, f/u fix/unfix, p plasticity, k/K stiffness, g/G damping, s save; h shows "
      "all), or with --script a scripted sequence of tool actions (see Documentation/Solids.md). Writes "
      "DIR/sculpted.lattice, DIR/sculpted.vtu, DIR/sculpted.png and DIR/report.json. Needs an X display for the "
      "window and the figure");
  sculpt->add_option("LATTICE", so->lattice, "Control lattice (.lattice)")->required();
  sculpt->add_option("--script", so->script, "Tool actions to apply, one per line, instead of the window");
  sculpt->add_option("--out", so->out, "Output directory (with --script: required; in the window: where s saves)")
      ->default_val(so->out);
  sculpt->add_option("--level", so->settings.levels, "Subdivisions carrying the mass points")
      ->default_val(so->settings.levels)
      ->check(numberBetween(0, 4, true));
  sculpt->add_option("--time-step", so->settings.timeStep, "Time step, s")
      ->default_val(so->settings.timeStep)
      ->check(positiveNumber());
  sculpt->add_option("--scheme", so->scheme, "Integration: semi-implicit (Euler) or explicit (the paper's)")
      ->default_val(so->scheme)
      ->check(CLI::IsMember({"semi-implicit", "explicit"}));
  sculpt->add_option("--mass", so->settings.material.mass, "Mass per mass point")
      ->default_val(so->settings.material.mass)
      ->check(positiveNumber());
  sculpt->add_option("--damping", so->settings.material.damping, "Damping per mass point, N s/mm")
      ->default_val(so->settings.material.damping)
      ->check(nonNegativeNumber());
  sculpt->add_option("--stiffness", so->settings.material.springStiffness, "Normal springs, N/mm")
      ->default_val(so->settings.material.springStiffness)
      ->check(positiveNumber());
  sculpt->add_option("--virtual-stiffness", so->settings.material.virtualStiffness,
                     "Virtual (angle) springs, N/mm")
      ->default_val(so->settings.material.virtualStiffness)
      ->check(positiveNumber());
  sculpt->add_option("--rope-stiffness", so->settings.ropeStiffness, "The rope, N/mm")
      ->default_val(so->settings.ropeStiffness)
      ->check(positiveNumber());
  sculpt->add_flag("!--no-figures", so->figure,
                   "Do not render sculpted.png (rendering needs an X display; without DISPLAY a private Xvfb is started)");
  sculpt->callback([so, sculpt] {
    if (!so->script.empty() && sculpt->count("--out") == 0)
      throw UsageError("--out DIR is required with --script (where the sculpted solid is written)");
    runSculpt(*so);
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
