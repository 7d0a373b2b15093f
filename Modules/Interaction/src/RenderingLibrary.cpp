// libDynSubRenderingLibrary.so's one exported symbol (RenderingLibrary.h): the
// figures, the viewer and the sculpting window behind function pointers.
#include "dynsub/RenderingLibrary.h"

#include "dynsub/Figures.h"
#include "dynsub/Sculptor.h"
#include "dynsub/SolidView.h"
#include "dynsub/TemporaryFileGuard.h"
#include "dynsub/Viewer.h"

namespace dynsub::rendering {
namespace {

void runViewer(ViewerInput input) {
  Viewer viewer(std::move(input));
  viewer.run();
}

void runSculptor(const Lattice& control, const SculptSettings& settings,
                 std::function<std::string(const Sculpture&)> save) {
  Sculptor sculptor(control, settings, std::move(save));
  sculptor.run();
}

}  // namespace
}  // namespace dynsub::rendering

// The library is built with hidden visibility: this is all it exports.
extern "C" __attribute__((visibility("default"))) const dynsub::rendering::Functions* dynsubRenderingFunctions() {
  using namespace dynsub;
  static const rendering::Functions table{
      [](std::string* why) { return figureDisplay(why); },
      &prepareFigureDisplay,
      &writeFigures,
      &writeSculptureFigure,
      &rendering::runViewer,
      &rendering::runSculptor,
      &temporaryfiles::useChannel};
  return &table;
}
