// Opens libDynSubGeometryFormats.so (GeometryFormats.h says why it is a
// library of its own).
#include "GeometryFormats.h"

#include "dynsub/OwnLibrary.h"

namespace dynsub::geometryformats {

const Functions& functions() {
  using Entry = const Functions* (*)();
  static const Functions* const loaded = reinterpret_cast<Entry>(
      openOwnLibrary(DYNSUB_GEOMETRY_FORMATS_NAME, DYNSUB_GEOMETRY_FORMATS_BUILD_PATH, kFunctionsSymbol,
                     "library that reads and writes OBJ, PLY and STL files through VTK"))();
  return *loaded;
}

}  // namespace dynsub::geometryformats
