// Files written by VtkXmlWriter read back through VTK's own XML reader, value
// for value: arrays across block boundaries, a block exactly full, empty
// arrays, strings, and several components.
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

#include <gtest/gtest.h>
#include <vtkCallbackCommand.h>
#include <vtkCellArray.h>
#include <vtkCellData.h>
#include <vtkDataArray.h>
#include <vtkFieldData.h>
#include <vtkNew.h>
#include <vtkPointData.h>
#include <vtkPolyData.h>
#include <vtkStringArray.h>
#include <vtkXMLPolyDataReader.h>

#include "dynsub/Error.h"
#include "dynsub/VtkXmlWriter.h"

namespace fs = std::filesystem;
using namespace dynsub;

namespace {

std::string scratch(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / "dynsub-vtkxml";
  fs::create_directories(dir);
  return (dir / name).string();
}

// n triangles over points 0..n+1, as a strip of fans would have them.
vtkxml::Dataset triangles(int points, int triangles, std::vector<double>& xyz) {
  xyz.resize(3 * static_cast<std::size_t>(points));
  for (std::size_t i = 0; i < xyz.size(); ++i) xyz[i] = std::sin(0.37 * static_cast<double>(i)) * 1e3 + 1e-9 * i;
  std::vector<int32_t> connectivity, offsets, element;
  std::vector<uint8_t> type;
  for (int t = 0; t < triangles; ++t) {
    for (int k = 0; k < 3; ++k) connectivity.push_back((t + k) % points);
    offsets.push_back(3 * (t + 1));
    element.push_back(t * 7 - 5);
    type.push_back(static_cast<uint8_t>(t % 2));
  }
  vtkxml::Dataset data;
  data.type = "PolyData";
  data.fieldData.push_back(vtkxml::stringArray("SPACE", {"LPS", "second & <third>"}));
  data.pieceAttributes = " NumberOfPoints=\"" + std::to_string(points) +
                         "\" NumberOfVerts=\"0\" NumberOfLines=\"0\" NumberOfStrips=\"0\" NumberOfPolys=\"" +
                         std::to_string(triangles) + "\"";
  data.sections.push_back({"PointData", "", {vtkxml::float64Array("Normals", xyz, 3)}});
  data.sections.push_back(
      {"CellData", "", {vtkxml::uint8Array("ElementType", type, true), vtkxml::int32Array("Element", element, true)}});
  data.sections.push_back({"Points", "", {vtkxml::float64Array("Points", xyz, 3)}});
  for (const char* empty : {"Verts", "Lines", "Strips"})
    data.sections.push_back({empty, "", {vtkxml::int64Array("connectivity", {}), vtkxml::int64Array("offsets", {})}});
  data.sections.push_back(
      {"Polys", "", {vtkxml::int32Array("connectivity", connectivity), vtkxml::int32Array("offsets", offsets)}});
  return data;
}

// Reads `path` with VTK, failing the test on any error VTK reports.
vtkSmartPointer<vtkPolyData> readBack(const std::string& path) {
  vtkNew<vtkXMLPolyDataReader> reader;
  vtkNew<vtkCallbackCommand> onError;
  bool failed = false;
  onError->SetClientData(&failed);
  onError->SetCallback([](vtkObject*, unsigned long, void* client, void*) { *static_cast<bool*>(client) = true; });
  reader->AddObserver(vtkCommand::ErrorEvent, onError);
  reader->SetFileName(path.c_str());
  reader->Update();
  EXPECT_FALSE(failed) << "VTK reported an error reading " << path;
  EXPECT_EQ(reader->GetErrorCode(), 0);
  auto data = vtkSmartPointer<vtkPolyData>::New();
  data->ShallowCopy(reader->GetOutput());
  return data;
}

void expectSame(int points, int cells) {
  std::vector<double> xyz;
  const vtkxml::Dataset data = triangles(points, cells, xyz);
  const std::string path = scratch("p" + std::to_string(points) + "c" + std::to_string(cells) + ".vtp");
  vtkxml::writeDataset(data, path, path);
  vtkSmartPointer<vtkPolyData> back = readBack(path);
  ASSERT_EQ(back->GetNumberOfPoints(), points);
  ASSERT_EQ(back->GetNumberOfPolys(), cells);
  vtkDataArray* normals = back->GetPointData()->GetArray("Normals");
  ASSERT_NE(normals, nullptr);
  ASSERT_EQ(normals->GetNumberOfComponents(), 3);
  for (int i = 0; i < points; ++i) {
    double p[3];
    back->GetPoint(i, p);
    for (int a = 0; a < 3; ++a) {
      ASSERT_EQ(p[a], xyz[3 * i + a]) << "point " << i;  // exact: the bytes are the doubles
      ASSERT_EQ(normals->GetComponent(i, a), xyz[3 * i + a]);
    }
  }
  vtkDataArray* element = back->GetCellData()->GetArray("Element");
  vtkDataArray* type = back->GetCellData()->GetArray("ElementType");
  ASSERT_NE(element, nullptr);
  ASSERT_NE(type, nullptr);
  EXPECT_EQ(element->GetDataType(), VTK_INT);
  EXPECT_EQ(type->GetDataType(), VTK_UNSIGNED_CHAR);
  vtkNew<vtkIdList> ids;
  for (int t = 0; t < cells; ++t) {
    ASSERT_EQ(element->GetTuple1(t), t * 7 - 5);
    ASSERT_EQ(type->GetTuple1(t), t % 2);
    back->GetPolys()->GetCellAtId(t, ids);
    ASSERT_EQ(ids->GetNumberOfIds(), 3);
    for (int k = 0; k < 3; ++k) ASSERT_EQ(ids->GetId(k), (t + k) % points);
  }
  auto* space = vtkStringArray::SafeDownCast(back->GetFieldData()->GetAbstractArray("SPACE"));
  ASSERT_NE(space, nullptr);
  ASSERT_EQ(space->GetNumberOfValues(), 2);
  EXPECT_EQ(space->GetValue(0), "LPS");
  EXPECT_EQ(space->GetValue(1), "second & <third>");
}

TEST(VtkXmlWriter, VtkReadsBackEveryValue) {
  expectSame(5, 3);  // every array shorter than a block
  // 8192 triangles: the Int32 cell arrays fill exactly one 32 KiB block (the
  // header's last-block size 0); 5000 points: 120 000 bytes, four blocks.
  expectSame(5000, 8192);
  expectSame(20000, 40001);  // many blocks, the last one short
}

TEST(VtkXmlWriter, RangesAreTheMagnitudesForVectors) {
  const vtkxml::DataArray vectors = vtkxml::float64Array("v", {3, 4, 0, 0, 0, -2}, 3);
  ASSERT_TRUE(vectors.hasRange);
  EXPECT_EQ(vectors.tuples, 2);
  EXPECT_EQ(vectors.rangeMin, 2.0);
  EXPECT_EQ(vectors.rangeMax, 5.0);
  const vtkxml::DataArray values = vtkxml::int32Array("i", {4, -7, 2}, true);
  EXPECT_EQ(values.rangeMin, -7.0);
  EXPECT_EQ(values.rangeMax, 4.0);
  EXPECT_FALSE(vtkxml::int32Array("topology", {1, 2}).hasRange);
  EXPECT_THROW(vtkxml::float64Array("v", {1, 2}, 3), Error);  // values that do not fill the tuples
}

TEST(VtkXmlWriter, AFileThatCannotBeWrittenIsNamed) {
  std::vector<double> xyz;
  const vtkxml::Dataset data = triangles(5, 3, xyz);
  try {
    vtkxml::writeDataset(data, "/nonexistent-dynsub/out.vtp", "asked-for.vtp");
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("asked-for.vtp"), std::string::npos) << e.what();
  }
}

}  // namespace
