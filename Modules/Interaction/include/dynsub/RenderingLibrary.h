#pragma once
// What the programs draw with VTK's rendering stack: the figures, the viewer
// and the sculpting window. They live in a library of their own,
// libDynSubRenderingLibrary.so in the build's lib/ directory, opened at the first
// call of functions() (OwnLibrary.h), so that a run that draws nothing starts
// without OpenGL, FreeType, VTK's charts and the MPI that VTK's filters bring:
// loading those took 13 ms of every command (`dynsub --version` 38 against
// 25 ms without them; Documentation/Performance.md, nineteenth session).
#include <functional>
#include <string>

#include "dynsub/FigureInputs.h"
#include "dynsub/Sculpting.h"
#include "dynsub/ViewerInput.h"

namespace dynsub::rendering {

// Figures.h, Viewer.h, Sculptor.h and SolidView.h's calls, as function
// pointers: RenderingLibrary.cpp fills them in the library, which exports
// them through one C symbol (kFunctionsSymbol).
struct Functions {
  bool (*figureDisplay)(std::string* why);
  void (*prepareFigureDisplay)();
  void (*writeFigures)(const FigureInputs& inputs, const FigureFiles& files);
  void (*writeSculptureFigure)(const Sculpture& sculpture, const std::string& path);
  // Builds the window and runs its event loop until it closes.
  void (*runViewer)(ViewerInput input);
  void (*runSculptor)(const Lattice& control, const SculptSettings& settings,
                      std::function<std::string(const Sculpture&)> save);
  // Hands the library the program's temporary-file guard (TemporaryFileGuard.h).
  void (*useTemporaryFileGuard)(int channel);
};
inline constexpr const char* kFunctionsSymbol = "dynsubRenderingFunctions";

// The library's functions, loaded at the first call (thread-safe). Throws
// dynsub::Error when the library cannot be opened.
const Functions& functions();

// The functions when figures can be drawn: the library opened and a display
// ready (Figures.h: figureDisplay). Otherwise null, with `why`, for runs whose
// figures are optional.
const Functions* figureFunctions(std::string& why);

}  // namespace dynsub::rendering
