// libDynSubGeometryFormats.so: VTK's OBJ, PLY and STL readers and writers
// (GeometryFormats.h says why this is a library of its own).
#include "GeometryFormats.h"

#include <vtkOBJReader.h>
#include <vtkOBJWriter.h>
#include <vtkPLYReader.h>
#include <vtkPLYWriter.h>
#include <vtkSTLReader.h>
#include <vtkSTLWriter.h>

namespace dynsub::geometryformats {
namespace {

template <typename Object>
Object* named(Object* object, const std::string& path) {
  object->SetFileName(path.c_str());
  return object;
}

vtkAbstractPolyDataReader* newReader(const std::string& extension, const std::string& path) {
  if (extension == ".obj") return named(vtkOBJReader::New(), path);
  if (extension == ".ply") return named(vtkPLYReader::New(), path);
  if (extension == ".stl") return named(vtkSTLReader::New(), path);
  return nullptr;
}

vtkWriter* newWriter(const std::string& extension, const std::string& path) {
  if (extension == ".obj") return named(vtkOBJWriter::New(), path);
  if (extension == ".ply") {
    vtkPLYWriter* writer = named(vtkPLYWriter::New(), path);
    writer->SetFileTypeToBinary();
    return writer;
  }
  if (extension == ".stl") {
    vtkSTLWriter* writer = named(vtkSTLWriter::New(), path);
    writer->SetFileTypeToBinary();
    return writer;
  }
  return nullptr;
}

}  // namespace
}  // namespace dynsub::geometryformats

// The library's one exported symbol (it is built with hidden visibility).
extern "C" __attribute__((visibility("default"))) const dynsub::geometryformats::Functions*
dynsubGeometryFormatsFunctions() {
  static const dynsub::geometryformats::Functions table{&dynsub::geometryformats::newReader,
                                                        &dynsub::geometryformats::newWriter};
  return &table;
}
