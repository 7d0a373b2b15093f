#pragma once
// Private to the SurfaceIO module: VTK's readers and writers of OBJ, PLY and
// STL files, in a library of their own (libDynSubGeometryFormats.so,
// GeometryFormats.cpp) opened when a program first reads or writes one of
// those files. VTK's geometry IO brings about thirty libraries with it
// (image IO, rendering core, codecs), which every command loaded at start,
// 7-15 ms each time, while most (segment, fit on points, the outputs'
// .vtp) never use them (Documentation/Performance.md).
#include <string>

class vtkAbstractPolyDataReader;
class vtkWriter;

namespace dynsub::geometryformats {

struct Functions {
  // A new reader (the caller deletes it) of the file `path` in the format of
  // `extension` (".obj", ".ply" or ".stl"), its file name set; nullptr for
  // another extension.
  vtkAbstractPolyDataReader* (*newReader)(const std::string& extension, const std::string& path);
  // A new writer of the same formats (PLY and STL binary), its file name set.
  vtkWriter* (*newWriter)(const std::string& extension, const std::string& path);
};
inline constexpr const char* kFunctionsSymbol = "dynsubGeometryFormatsFunctions";

// The library's functions, loaded at the first call (thread-safe). Throws
// dynsub::Error when the library cannot be opened.
const Functions& functions();

}  // namespace dynsub::geometryformats
