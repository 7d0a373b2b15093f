// Opens libDynSubGeometryFormats.so (GeometryFormats.h says why it is a
// library of its own).
#include "GeometryFormats.h"

#include "dynsub/OwnLibrary.h"

namespace dynsub::geometryformats {

const Functions& functions() {
  static const Functions& loaded =
      ownLibraryTable<Functions>(DYNSUB_GEOMETRY_FORMATS_NAME, DYNSUB_GEOMETRY_FORMATS_BUILD_PATH, kFunctionsSymbol,
                                 "library that reads OBJ, PLY, STL and VTK XML polydata files through VTK");
  return loaded;
}

}  // namespace dynsub::geometryformats
