// dynsub: segmentation and shape recovery with dynamic Catmull-Clark
// subdivision surfaces. Exit codes: 0 success, 1 an error in the input or the
// run (the message names the file and problem), 2 a usage error.
#include <iostream>
#include <new>

#include <CLI/CLI.hpp>

#include "CommandLine.h"
#include "Commands.h"
#include "dynsub/AtomicOutput.h"
#include "dynsub/Error.h"

int main(int argc, char** argv) {
  dynsub::removeTemporariesOnInterrupt();
  CLI::App app{
      "DynSub: dynamic Catmull-Clark subdivision surfaces for segmenting 3D medical images and "
      "recovering shapes.\n"
      "A smooth surface of any genus, defined by a small control mesh, moves under Lagrangian "
      "dynamics toward image edges and expert landmarks, and refines itself until it fits.\n"
      "Coordinates are in mm. Run 'dynsub COMMAND --help' for each command.",
      "dynsub"};
  app.set_version_flag("--version", std::string("dynsub ") + DYNSUB_VERSION);
  app.require_subcommand(1);
  dynsub::app::addLimitCommand(app);
  dynsub::app::addMeshCommand(app);
  dynsub::app::addFitCommand(app);
  dynsub::app::addDeformCommand(app);
  dynsub::app::addSegmentCommand(app);
  dynsub::app::addEvaluateCommand(app);
  dynsub::app::addSubjectCommand(app);
  dynsub::app::addRenderCommand(app);
  dynsub::app::addViewCommand(app);
  dynsub::app::addSolidCommand(app);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& error) {
    const int code = app.exit(error);
    if (code == 0) return 0;
    const std::string hint = dynsub::app::didYouMean(app, std::vector<std::string>(argv + 1, argv + argc));
    if (!hint.empty()) std::cerr << "dynsub: " << hint << '\n';
    return 2;
  } catch (const dynsub::Error& error) {
    std::cerr << "dynsub: error: " << dynsub::withoutTemporaryPrefix(error.what()) << '\n';
    return dynamic_cast<const dynsub::UsageError*>(&error) ? 2 : 1;
  } catch (const std::bad_alloc&) {
    std::cerr << "dynsub: error: out of memory: the run needed more than this machine (or its limit, ulimit -v) "
                 "gives. An output's size grows as the square or the cube of --samples-per-face and of --level: a "
                 "smaller value needs far less\n";
    return 1;
  } catch (const std::exception& error) {
    std::cerr << "dynsub: unexpected error: " << error.what() << '\n';
    return 1;
  }
  return 0;
}
