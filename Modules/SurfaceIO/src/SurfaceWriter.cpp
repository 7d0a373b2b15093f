#include "dynsub/SurfaceWriter.h"

#include <algorithm>
#include <filesystem>

#include <vtkCellArray.h>
#include <vtkCellData.h>
#include <vtkDoubleArray.h>
#include <vtkIntArray.h>
#include <vtkNew.h>
#include <vtkOBJWriter.h>
#include <vtkPLYWriter.h>
#include <vtkPointData.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkSTLWriter.h>
#include <vtkUnsignedCharArray.h>
#include <vtkXMLPolyDataWriter.h>

#include "dynsub/AtomicOutput.h"
#include "dynsub/Error.h"
#include "dynsub/FileNames.h"

namespace dynsub {

namespace {


vtkNew<vtkPolyData> toPolyData(const TriangleSurface& surface) {
  vtkNew<vtkPoints> points;
  points->SetDataTypeToDouble();
  points->SetNumberOfPoints(surface.points.rows());
  vtkNew<vtkDoubleArray> normals;
  normals->SetName("Normals");
  normals->SetNumberOfComponents(3);
  normals->SetNumberOfTuples(surface.points.rows());
  for (Eigen::Index i = 0; i < surface.points.rows(); ++i) {
    points->SetPoint(i, surface.points(i, 0), surface.points(i, 1), surface.points(i, 2));
    normals->SetTuple3(i, surface.normals(i, 0), surface.normals(i, 1), surface.normals(i, 2));
  }
  vtkNew<vtkCellArray> triangles;
  vtkNew<vtkUnsignedCharArray> type;
  type->SetName("ElementType");
  vtkNew<vtkIntArray> element;
  element->SetName("Element");
  for (size_t t = 0; t < surface.triangles.size(); ++t) {
    const vtkIdType ids[3] = {surface.triangles[t][0], surface.triangles[t][1], surface.triangles[t][2]};
    triangles->InsertNextCell(3, ids);
    type->InsertNextValue(static_cast<unsigned char>(surface.triangleType[t]));
    element->InsertNextValue(surface.triangleElement[t]);
  }
  vtkNew<vtkPolyData> polyData;
  polyData->SetPoints(points);
  polyData->SetPolys(triangles);
  polyData->GetPointData()->SetNormals(normals);
  polyData->GetCellData()->AddArray(type);
  polyData->GetCellData()->AddArray(element);
  return polyData;
}

}  // namespace

std::vector<std::string> triangleSurfaceExtensions() { return {".vtp", ".obj", ".ply", ".stl"}; }

void writeTriangleSurface(const TriangleSurface& surface, const std::string& path) {
  const std::string extension = lowerCaseExtension(path);
  const std::vector<std::string> known = triangleSurfaceExtensions();
  if (std::find(known.begin(), known.end(), extension) == known.end()) {
    throw Error(path, "unknown surface format '" + extension + "' (expected .vtp, .obj, .ply or .stl)");
  }
  if (!surface.points.allFinite()) throw Error(path, "the surface has non-finite coordinates; nothing written");
  AtomicOutput output(path);
  vtkNew<vtkPolyData> polyData = toPolyData(surface);
  int written = 0;
  if (extension == ".vtp") {
    vtkNew<vtkXMLPolyDataWriter> writer;
    writer->SetFileName(output.temporaryPath().c_str());
    writer->SetInputData(polyData);
    writer->SetDataModeToAppended();
    written = writer->Write();
  } else if (extension == ".obj") {
    vtkNew<vtkOBJWriter> writer;
    writer->SetFileName(output.temporaryPath().c_str());
    writer->SetInputData(polyData);
    written = writer->Write();
  } else if (extension == ".ply") {
    vtkNew<vtkPLYWriter> writer;
    writer->SetFileName(output.temporaryPath().c_str());
    writer->SetInputData(polyData);
    writer->SetFileTypeToBinary();
    written = writer->Write();
  } else {
    vtkNew<vtkSTLWriter> writer;
    writer->SetFileName(output.temporaryPath().c_str());
    writer->SetInputData(polyData);
    writer->SetFileTypeToBinary();
    written = writer->Write();
  }
  if (written != 1) throw Error(path, "VTK could not write the file");
  output.commit();
}

}  // namespace dynsub
