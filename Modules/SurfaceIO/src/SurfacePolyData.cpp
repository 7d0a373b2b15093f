#include "dynsub/SurfacePolyData.h"

#include <cmath>
#include <filesystem>

#include <vtkCellArray.h>
#include <vtkCellArrayIterator.h>
#include <vtkCellData.h>
#include <vtkDoubleArray.h>
#include <vtkFieldData.h>
#include <vtkIntArray.h>
#include <vtkNew.h>
#include <vtkPLYReader.h>
#include <vtkPolyDataReader.h>
#include <vtkSTLReader.h>
#include <vtkAbstractPolyDataReader.h>
#include <vtkPointData.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkUnsignedCharArray.h>
#include <vtkXMLPolyDataReader.h>

#include "dynsub/Error.h"
#include "dynsub/FileNames.h"
#include "dynsub/MeshIO.h"
#include "dynsub/VtkErrors.h"
#include "SlicerSpace.h"

namespace dynsub {

vtkSmartPointer<vtkPolyData> toPolyData(const TriangleSurface& surface) {
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
  // 32-bit point ids where they fit (always, below 2^31 points): the
  // connectivity and offsets were half of a fitted surface's bytes as 64-bit
  // ids, all to be compressed and written.
  if (surface.points.rows() < (Eigen::Index{1} << 31)) triangles->Use32BitStorage();
  triangles->AllocateExact(static_cast<vtkIdType>(surface.triangles.size()),
                           3 * static_cast<vtkIdType>(surface.triangles.size()));
  vtkNew<vtkUnsignedCharArray> type;
  type->SetName("ElementType");
  type->SetNumberOfValues(static_cast<vtkIdType>(surface.triangles.size()));
  vtkNew<vtkIntArray> element;
  element->SetName("Element");
  element->SetNumberOfValues(static_cast<vtkIdType>(surface.triangles.size()));
  for (size_t t = 0; t < surface.triangles.size(); ++t) {
    const vtkIdType ids[3] = {surface.triangles[t][0], surface.triangles[t][1], surface.triangles[t][2]};
    triangles->InsertNextCell(3, ids);
    type->SetValue(static_cast<vtkIdType>(t), static_cast<unsigned char>(surface.triangleType[t]));
    element->SetValue(static_cast<vtkIdType>(t), surface.triangleElement[t]);
  }
  auto polyData = vtkSmartPointer<vtkPolyData>::New();
  polyData->SetPoints(points);
  polyData->SetPolys(triangles);
  polyData->GetPointData()->SetNormals(normals);
  polyData->GetCellData()->AddArray(type);
  polyData->GetCellData()->AddArray(element);
  return polyData;
}

void addPointData(vtkPolyData* polyData, const std::string& name, const Eigen::VectorXd& values) {
  vtkNew<vtkDoubleArray> array;
  array->SetName(name.c_str());
  array->SetNumberOfValues(values.size());
  for (Eigen::Index i = 0; i < values.size(); ++i) array->SetValue(i, values(i));
  polyData->GetPointData()->AddArray(array);
}

std::string farName(const std::string& scalars) { return scalars + "_far"; }

void addFarDistance(vtkPolyData* polyData, const std::string& name, double far) {
  vtkNew<vtkDoubleArray> array;
  array->SetName(farName(name).c_str());
  array->InsertNextValue(far);
  polyData->GetFieldData()->AddArray(array);
}

namespace {

// The polygons of an OBJ file read by DynSub's own reader (which checks the
// indices).
vtkSmartPointer<vtkPolyData> toPolyData(const PolygonData& data) {
  vtkNew<vtkPoints> points;
  points->SetDataTypeToDouble();
  points->SetNumberOfPoints(data.points.rows());
  for (Eigen::Index i = 0; i < data.points.rows(); ++i)
    points->SetPoint(i, data.points(i, 0), data.points(i, 1), data.points(i, 2));
  vtkNew<vtkCellArray> polygons;
  for (const Polygon& face : data.faces) {
    polygons->InsertNextCell(static_cast<vtkIdType>(face.size()));
    for (const int corner : face) polygons->InsertCellPoint(corner);
  }
  auto polyData = vtkSmartPointer<vtkPolyData>::New();
  polyData->SetPoints(points);
  polyData->SetPolys(polygons);
  return polyData;
}

// `reader`'s file name is set.
vtkSmartPointer<vtkPolyData> readWith(vtkAlgorithm* reader, const std::string& path) {
  VtkErrors errors;
  errors.watch(reader);
  reader->Update();
  if (!errors.first().empty()) throw Error(path, "VTK could not read the surface: " + errors.reason());
  auto polyData = vtkSmartPointer<vtkPolyData>::New();
  polyData->ShallowCopy(vtkPolyData::SafeDownCast(reader->GetOutputDataObject(0)));
  return polyData;
}

// x and y negated in a 3-vector array.
void halfTurn(vtkDataArray* array) {
  if (!array || array->GetNumberOfComponents() != 3) return;
  for (vtkIdType i = 0; i < array->GetNumberOfTuples(); ++i) {
    double v[3];
    array->GetTuple(i, v);
    array->SetTuple3(i, -v[0], -v[1], v[2]);
  }
  array->Modified();
}

// RAS to LPS: x and y negated, a half turn about z, for the points and the
// point and cell normals and vectors, as Slicer turns them; the polygons
// keep their orientation.
vtkSmartPointer<vtkPolyData> toLps(vtkPolyData* polyData) {
  halfTurn(polyData->GetPoints()->GetData());
  polyData->GetPoints()->Modified();
  for (vtkDataSetAttributes* data : {static_cast<vtkDataSetAttributes*>(polyData->GetPointData()),
                                     static_cast<vtkDataSetAttributes*>(polyData->GetCellData())}) {
    halfTurn(data->GetNormals());
    if (data->GetVectors() != data->GetNormals()) halfTurn(data->GetVectors());
  }
  return polyData;
}

}  // namespace

vtkSmartPointer<vtkPolyData> readSurfacePolyData(const std::string& path) {
  if (!std::filesystem::is_regular_file(path)) throw Error(path, "no such file");
  const std::string extension = lowerCaseExtension(path);
  vtkSmartPointer<vtkPolyData> polyData;
  // A file 3D Slicer marked as RAS is turned into LPS (SlicerSpace.h).
  std::string space;
  if (extension == ".vtp") {
    vtkNew<vtkXMLPolyDataReader> reader;
    reader->SetFileName(path.c_str());
    polyData = readWith(reader.GetPointer(), path);
    space = fieldSpace(polyData);
  } else if (extension == ".vtk") {
    vtkNew<vtkPolyDataReader> reader;
    reader->SetFileName(path.c_str());
    polyData = readWith(reader.GetPointer(), path);
    if (reader->GetHeader()) space = statedSpace(reader->GetHeader());
  } else if (extension == ".obj") {
    // DynSub's own OBJ reader: VTK's reads "v nan 1 0" as the origin without
    // a word, where this one names the line.
    polyData = toPolyData(readPolygonData(path));
    space = commentSpace(path);
  } else if (extension == ".ply") {
    vtkNew<vtkPLYReader> reader;
    reader->SetFileName(path.c_str());
    polyData = readWith(reader.GetPointer(), path);
    space = commentSpace(path);
  } else if (extension == ".stl") {
    vtkNew<vtkSTLReader> reader;
    reader->SetFileName(path.c_str());
    polyData = readWith(reader.GetPointer(), path);
    if (reader->GetHeader()) space = statedSpace(reader->GetHeader());
    if (vtkUnsignedCharArray* header = reader->GetBinaryHeader(); header && space.empty()) {
      std::string text;
      for (vtkIdType i = 0; i < header->GetNumberOfValues(); ++i) text += static_cast<char>(header->GetValue(i));
      space = statedSpace(text);
    }
  } else {
    throw Error(path, "unknown surface format '" + extension + "' (expected .vtp, .vtk, .obj, .ply or .stl)");
  }
  if (polyData->GetNumberOfPolys() == 0) throw Error(path, "the file holds no surface polygons");
  if (space == "RAS") polyData = toLps(polyData);
  for (vtkIdType i = 0; i < polyData->GetNumberOfPoints(); ++i) {
    double p[3];
    polyData->GetPoint(i, p);
    if (!std::isfinite(p[0]) || !std::isfinite(p[1]) || !std::isfinite(p[2]))
      throw Error(path, "point " + std::to_string(i) + " has a non-finite coordinate");
  }
  // VTK's readers keep a cell's point indices as written: one past the
  // points would be read out of bounds by every filter after.
  const vtkIdType pointCount = polyData->GetNumberOfPoints();
  const std::pair<const char*, vtkCellArray*> cellArrays[] = {{"vertex cell", polyData->GetVerts()},
                                                              {"line", polyData->GetLines()},
                                                              {"polygon", polyData->GetPolys()},
                                                              {"triangle strip", polyData->GetStrips()}};
  for (const auto& [what, cells] : cellArrays) {
    if (!cells) continue;
    auto cell = vtk::TakeSmartPointer(cells->NewIterator());
    for (cell->GoToFirstCell(); !cell->IsDoneWithTraversal(); cell->GoToNextCell()) {
      vtkIdType size = 0;
      const vtkIdType* ids = nullptr;
      cell->GetCurrentCell(size, ids);
      for (vtkIdType k = 0; k < size; ++k)
        if (ids[k] < 0 || ids[k] >= pointCount)
          throw Error(path, std::string(what) + " " + std::to_string(cell->GetCurrentCellId()) + " uses point " +
                                std::to_string(ids[k]) + ", but the file has " + std::to_string(pointCount) +
                                " points (both counted from 0)");
    }
  }
  return polyData;
}

MatrixX3 pointsOf(vtkPolyData* polyData) {
  MatrixX3 points(polyData->GetNumberOfPoints(), 3);
  for (vtkIdType i = 0; i < polyData->GetNumberOfPoints(); ++i) {
    double p[3];
    polyData->GetPoint(i, p);
    points.row(i) << p[0], p[1], p[2];
  }
  return points;
}

MatrixX3 readSurfacePoints(const std::string& path) { return pointsOf(readSurfacePolyData(path)); }

}  // namespace dynsub
