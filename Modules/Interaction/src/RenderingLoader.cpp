// Opens libDynSubRenderingLibrary.so (RenderingLibrary.h says why it is a library of its own).
#include "dynsub/Error.h"
#include "dynsub/OwnLibrary.h"
#include "dynsub/RenderingLibrary.h"
#include "dynsub/TemporaryFileGuard.h"

namespace dynsub::rendering {

const Functions& functions() {
  // Never closed: VTK's object factories live until exit.
  static const Functions& loaded = [] () -> const Functions& {
    const Functions& table =
        ownLibraryTable<Functions>(DYNSUB_RENDERING_LIBRARY_NAME, DYNSUB_RENDERING_LIBRARY_BUILD_PATH,
                                   kFunctionsSymbol, "library that draws figures and windows with VTK");
    // Its own copy of the Core module tells the program's guard of its temporary files.
    table.useTemporaryFileGuard(temporaryfiles::channel());
    return table;
  }();
  return loaded;
}

const Functions* figureFunctions(std::string& why) {
  try {
    const Functions& draw = functions();
    return draw.figureDisplay(&why) ? &draw : nullptr;
  } catch (const Error& e) {
    why = e.what();
    return nullptr;
  }
}

}  // namespace dynsub::rendering
