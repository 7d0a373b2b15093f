#include "dynsub/VtkXmlWriter.h"

#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <string>

#include <gtest/gtest.h>
#include <vtkCellArray.h>
#include <vtkDoubleArray.h>
#include <vtkIdList.h>
#include <vtkNew.h>
#include <vtkPointData.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkUnstructuredGrid.h>
#include <vtkXMLPolyDataReader.h>
#include <vtkXMLUnstructuredGridReader.h>

#include "dynsub/Error.h"

namespace fs = std::filesystem;

namespace {

fs::path scratch(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / ("dynsub-vtkxml-" + std::to_string(::getpid()));
  fs::create_directories(dir);
  return dir / name;
}

// A triangle fan of n triangles around the origin with one value per point:
// more than one LZ4 block (32 KiB) of points for n = 5000.
vtkNew<vtkPolyData> fan(int n) {
  vtkNew<vtkPolyData> data;
  vtkNew<vtkPoints> points;
  points->SetDataTypeToDouble();
  vtkNew<vtkDoubleArray> values;
  values->SetName("Value");
  points->InsertNextPoint(0, 0, 0);
  values->InsertNextValue(0);
  vtkNew<vtkCellArray> triangles;
  for (int i = 0; i <= n; ++i) {
    const double a = 6.283185307179586 * i / n;
    points->InsertNextPoint(std::cos(a), std::sin(a), 0.001 * i);
    values->InsertNextValue(1.0 / (i + 1));
    if (i > 0) {
      const vtkIdType ids[3] = {0, i, i + 1};
      triangles->InsertNextCell(3, ids);
    }
  }
  data->SetPoints(points);
  data->SetPolys(triangles);
  data->GetPointData()->AddArray(values);
  return data;
}

TEST(VtkXmlWriter, VtkReadsBackEveryPolyDataValue) {
  const vtkNew<vtkPolyData> written = fan(5000);
  const fs::path path = scratch("fan.vtp");
  dynsub::writeVtkXml(written, path.string(), "fan.vtp");
  vtkNew<vtkXMLPolyDataReader> reader;
  reader->SetFileName(path.c_str());
  reader->Update();
  vtkPolyData* read = reader->GetOutput();
  ASSERT_EQ(read->GetNumberOfPoints(), written->GetNumberOfPoints());
  ASSERT_EQ(read->GetNumberOfPolys(), written->GetNumberOfPolys());
  auto* values = vtkDoubleArray::SafeDownCast(read->GetPointData()->GetArray("Value"));
  ASSERT_NE(values, nullptr);
  for (vtkIdType i = 0; i < read->GetNumberOfPoints(); ++i) {
    double a[3], b[3];
    read->GetPoint(i, a);
    written->GetPoint(i, b);
    for (int c = 0; c < 3; ++c) ASSERT_EQ(a[c], b[c]);  // doubles, written losslessly
    ASSERT_EQ(values->GetValue(i), i == 0 ? 0.0 : 1.0 / static_cast<double>(i));
  }
}

TEST(VtkXmlWriter, VtkReadsBackAPolyhedron) {
  // A unit cube as one VTK_POLYHEDRON with its six faces.
  vtkNew<vtkUnstructuredGrid> grid;
  vtkNew<vtkPoints> points;
  for (int k = 0; k < 2; ++k)
    for (int j = 0; j < 2; ++j)
      for (int i = 0; i < 2; ++i) points->InsertNextPoint(i, j, k);
  grid->SetPoints(points);
  const vtkIdType corners[8] = {0, 1, 2, 3, 4, 5, 6, 7};
  const vtkIdType faces[] = {4, 0, 2, 3, 1, 4, 4, 5, 7, 6, 4, 0, 1, 5, 4, 4, 2, 6, 7, 3, 4, 0, 4, 6, 2, 4, 1, 3, 7, 5};
  grid->InsertNextCell(VTK_POLYHEDRON, 8, corners, 6, faces);
  const fs::path path = scratch("cube.vtu");
  dynsub::writeVtkXml(grid, path.string(), "cube.vtu");
  vtkNew<vtkXMLUnstructuredGridReader> reader;
  reader->SetFileName(path.c_str());
  reader->Update();
  vtkUnstructuredGrid* read = reader->GetOutput();
  ASSERT_EQ(read->GetNumberOfCells(), 1);
  EXPECT_EQ(read->GetCellType(0), VTK_POLYHEDRON);
  vtkNew<vtkIdList> stream;
  read->GetFaceStream(0, stream);
  ASSERT_EQ(stream->GetNumberOfIds(), 1 + 30);
  EXPECT_EQ(stream->GetId(0), 6);
  for (int f = 0; f < 30; ++f) EXPECT_EQ(stream->GetId(1 + f), faces[f]);
}

TEST(VtkXmlWriter, AFileThatCannotBeWrittenIsNamed) {
  const vtkNew<vtkPolyData> written = fan(10);
  const std::string path = (scratch("") / "no-such-directory" / "fan.vtp").string();
  try {
    dynsub::writeVtkXml(written, path, "fan.vtp");
    FAIL() << "no error";
  } catch (const dynsub::Error& e) {
    EXPECT_NE(std::string(e.what()).find("fan.vtp"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("could not be written"), std::string::npos) << e.what();
  }
  EXPECT_FALSE(fs::exists(path));
}

}  // namespace
