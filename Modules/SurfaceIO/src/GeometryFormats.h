#pragma once
// Private to the SurfaceIO module: VTK's readers of surface and point files
// (OBJ, PLY, STL and VTK XML polydata), in a library of their own
// (libDynSubGeometryFormats.so, GeometryFormats.cpp) opened when a program
// first reads one of those files. VTK's IO brings its core, data model and
// codecs, and its geometry IO about thirty libraries more (image IO,
// rendering core), which every command loaded at start while most (segment,
// fit on points, the outputs, which SurfaceWriter.cpp and VtkXmlWriter.h
// write themselves) never use them (Documentation/Performance.md).
#include <string>
#include <vector>

class vtkAbstractPolyDataReader;

namespace dynsub::geometryformats {

struct Functions {
  // A new reader (the caller deletes it) of the file `path` in the format of
  // `extension` (".obj", ".ply" or ".stl"), its file name set; nullptr for
  // another extension.
  vtkAbstractPolyDataReader* (*newReader)(const std::string& extension, const std::string& path);
  // Reads the points of the VTK XML polydata file `path` into `xyz` (x, y, z
  // of each in turn). Returns "" when it could, else what was wrong, for the
  // caller's error naming the file.
  std::string (*readXmlPolyDataPoints)(const std::string& path, std::vector<double>& xyz);
};
inline constexpr const char* kFunctionsSymbol = "dynsubGeometryFormatsFunctions";

// The library's functions, loaded at the first call (thread-safe). Throws
// dynsub::Error when the library cannot be opened.
const Functions& functions();

}  // namespace dynsub::geometryformats
