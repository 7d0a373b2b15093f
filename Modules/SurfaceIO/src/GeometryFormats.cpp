// libDynSubGeometryFormats.so: VTK's readers of OBJ, PLY, STL and VTK XML
// polydata (GeometryFormats.h says why this is a library of its own).
#include "GeometryFormats.h"

#include <vtkNew.h>
#include <vtkOBJReader.h>
#include <vtkPLYReader.h>
#include <vtkPolyData.h>
#include <vtkSTLReader.h>
#include <vtkXMLPolyDataReader.h>

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

std::string readXmlPolyDataPoints(const std::string& path, std::vector<double>& xyz) {
  vtkNew<vtkXMLPolyDataReader> reader;
  if (!reader->CanReadFile(path.c_str())) return "is not a VTK XML polydata file";
  reader->SetFileName(path.c_str());
  reader->Update();
  if (reader->GetErrorCode() != 0) return "could not be read (truncated or corrupt?)";
  vtkPolyData* data = reader->GetOutput();
  if (!data || !data->GetPoints() || data->GetNumberOfPoints() == 0) return "has no points";
  xyz.resize(3 * static_cast<std::size_t>(data->GetNumberOfPoints()));
  for (vtkIdType i = 0; i < data->GetNumberOfPoints(); ++i) data->GetPoint(i, xyz.data() + 3 * i);
  return "";
}

}  // namespace
}  // namespace dynsub::geometryformats

// The library's one exported symbol (it is built with hidden visibility).
extern "C" __attribute__((visibility("default"))) const dynsub::geometryformats::Functions*
dynsubGeometryFormatsFunctions() {
  static const dynsub::geometryformats::Functions table{&dynsub::geometryformats::newReader,
                                                        &dynsub::geometryformats::readXmlPolyDataPoints};
  return &table;
}
