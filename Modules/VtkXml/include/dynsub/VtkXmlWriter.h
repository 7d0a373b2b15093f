#pragma once
// VTK's XML data files (.vtp polydata, .vtu unstructured grids), written by
// VTK's own XML writer: appended raw binary, little-endian, LZ4-compressed
// blocks (fast to write and to read). VTK 8.1 and later, ParaView 5.5 and
// later and 3D Slicer 4.10 and later read them.
#include <string>

class vtkDataObject;

namespace dynsub {

// Writes `data` (a vtkPolyData or a vtkUnstructuredGrid) to `path`. Throws
// dynsub::Error naming `name` (the file the user asked for, when `path` is a
// temporary one) and the reason (a full disk, VTK's own message) when the
// file cannot be written; VTK's messages go into the error, not to stderr.
void writeVtkXml(vtkDataObject* data, const std::string& path, const std::string& name);

}  // namespace dynsub
