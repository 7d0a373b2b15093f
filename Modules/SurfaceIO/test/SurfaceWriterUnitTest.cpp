// Unit tests (no rendering): written surfaces read back through VTK's readers
// with the same points, triangles and element tags.
#include <sys/resource.h>

#include <cmath>
#include <csignal>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

#include <gtest/gtest.h>
#include <vtkCellData.h>
#include <vtkPointData.h>
#include <vtkDataArray.h>
#include <vtkFieldData.h>
#include <vtkIdList.h>
#include <vtkStringArray.h>
#include <vtkNew.h>
#include <vtkOBJReader.h>
#include <vtkPLYReader.h>
#include <vtkPolyDataReader.h>
#include <vtkPolyData.h>
#include <vtkSTLReader.h>
#include <vtkXMLPolyDataReader.h>

#include "dynsub/Error.h"
#include "dynsub/StandardMeshes.h"
#include "dynsub/SurfacePolyData.h"
#include "dynsub/SurfaceWriter.h"

namespace fs = std::filesystem;

namespace {

dynsub::TriangleSurface cubeSurface() {
  const dynsub::ControlMesh cube = dynsub::makeCube98();
  const dynsub::LimitSurface limit(cube);
  return dynsub::tessellate(limit, cube.points(), 2);
}

std::string scratch(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / "dynsub-surfaceio";
  fs::create_directories(dir);
  return (dir / name).string();
}

TEST(SurfaceWriter, VtpKeepsGeometryAndElementTags) {
  const dynsub::TriangleSurface surface = cubeSurface();
  const std::string path = scratch("cube.vtp");
  dynsub::writeTriangleSurface(surface, path);
  vtkNew<vtkXMLPolyDataReader> reader;
  reader->SetFileName(path.c_str());
  reader->Update();
  vtkPolyData* data = reader->GetOutput();
  ASSERT_EQ(data->GetNumberOfPoints(), surface.points.rows());
  ASSERT_EQ(data->GetNumberOfCells(), static_cast<vtkIdType>(surface.triangles.size()));
  double p[3];
  data->GetPoint(17, p);
  EXPECT_EQ(p[0], surface.points(17, 0));
  vtkDataArray* type = data->GetCellData()->GetArray("ElementType");
  ASSERT_NE(type, nullptr);
  int special = 0;
  for (vtkIdType c = 0; c < type->GetNumberOfTuples(); ++c) special += type->GetTuple1(c) == 1.0;
  // 8 valence-3 vertices x 3 special elements x 2 x 2 squares x 2 triangles.
  EXPECT_EQ(special, 8 * 3 * 2 * 2 * 2);
}

TEST(SurfaceWriter, VtpCarriesPointScalarsAndRefusesBadOnes) {
  const dynsub::TriangleSurface surface = cubeSurface();
  const Eigen::VectorXd values = surface.points.col(2).array() * 2.0 + 1.0;
  const std::string path = scratch("scalars.vtp");
  dynsub::writeTriangleSurface(surface, path, {{"edge_distance_mm", values}});
  vtkNew<vtkXMLPolyDataReader> reader;
  reader->SetFileName(path.c_str());
  reader->Update();
  vtkDataArray* array = reader->GetOutput()->GetPointData()->GetArray("edge_distance_mm");
  ASSERT_NE(array, nullptr);
  ASSERT_EQ(array->GetNumberOfTuples(), values.size());
  for (vtkIdType i = 0; i < array->GetNumberOfTuples(); i += 7) EXPECT_EQ(array->GetTuple1(i), values(i));
  // Without a far distance, no field array for it.
  EXPECT_EQ(reader->GetOutput()->GetFieldData()->GetArray("edge_distance_mm_far"), nullptr);
  // With one, a one-value field array beside the point data.
  dynsub::writeTriangleSurface(surface, path, {{"scan_distance_mm", values, 2.5}});
  reader->Modified();
  reader->Update();
  vtkDataArray* far = reader->GetOutput()->GetFieldData()->GetArray(dynsub::farName("scan_distance_mm").c_str());
  ASSERT_NE(far, nullptr);
  ASSERT_EQ(far->GetNumberOfTuples(), 1);
  EXPECT_EQ(far->GetTuple1(0), 2.5);
  // Wrong size, NaN, or a far distance that is negative or infinite: an error and no file.
  const std::string bad = scratch("bad_scalars.vtp");
  fs::remove(bad);
  EXPECT_THROW(dynsub::writeTriangleSurface(surface, bad, {{"short", values.head(3)}}), dynsub::Error);
  Eigen::VectorXd nan = values;
  nan(5) = std::nan("");
  EXPECT_THROW(dynsub::writeTriangleSurface(surface, bad, {{"nan", nan}}), dynsub::Error);
  EXPECT_THROW(dynsub::writeTriangleSurface(surface, bad, {{"far", values, -1.0}}), dynsub::Error);
  EXPECT_THROW(dynsub::writeTriangleSurface(surface, bad, {{"far", values, HUGE_VAL}}), dynsub::Error);
  EXPECT_FALSE(fs::exists(bad));
}

// 3D Slicer reads a model's coordinate system from the field-data string
// array SPACE; a surface in an image's physical space is marked LPS.
TEST(SurfaceWriter, VtpRecordsItsCoordinateSpaceForSlicer) {
  const dynsub::TriangleSurface surface = cubeSurface();
  const std::string path = scratch("lps.vtp");
  dynsub::writeTriangleSurface(surface, path, {}, "LPS");
  vtkNew<vtkXMLPolyDataReader> reader;
  reader->SetFileName(path.c_str());
  reader->Update();
  auto* space = vtkStringArray::SafeDownCast(reader->GetOutput()->GetFieldData()->GetAbstractArray("SPACE"));
  ASSERT_NE(space, nullptr);
  ASSERT_EQ(space->GetNumberOfValues(), 1);
  EXPECT_EQ(space->GetValue(0), "LPS");
  // Without a space nothing is claimed; an unknown one is refused, with no file.
  const std::string plain = scratch("plain.vtp");
  dynsub::writeTriangleSurface(surface, plain);
  reader->SetFileName(plain.c_str());
  reader->Update();
  EXPECT_EQ(reader->GetOutput()->GetFieldData()->GetAbstractArray("SPACE"), nullptr);
  const std::string bad = scratch("xyz_space.vtp");
  fs::remove(bad);
  EXPECT_THROW(dynsub::writeTriangleSurface(surface, bad, {}, "XYZ"), dynsub::Error);
  EXPECT_FALSE(fs::exists(bad));
}

TEST(SurfaceWriter, LegacyVtkReadsBackWithItsSpaceAndPointData) {
  // The legacy format is what nipype's Slicer interfaces and older Slicer
  // scenes name models by: VTK's legacy reader gets every point, triangle,
  // normal and scalar back (floats), and the title line says the space.
  const dynsub::TriangleSurface surface = cubeSurface();
  Eigen::VectorXd distance(surface.points.rows());
  for (Eigen::Index i = 0; i < distance.size(); ++i) distance[i] = 0.25 * static_cast<double>(i % 7);
  const std::string path = scratch("cube.vtk");
  dynsub::writeTriangleSurface(surface, path, {{"edge_distance_mm", distance}}, "LPS");
  vtkNew<vtkPolyDataReader> reader;
  reader->SetFileName(path.c_str());
  reader->Update();
  EXPECT_NE(std::string(reader->GetHeader()).find("SPACE=LPS"), std::string::npos);
  vtkPolyData* data = reader->GetOutput();
  ASSERT_EQ(data->GetNumberOfPoints(), surface.points.rows());
  ASSERT_EQ(data->GetNumberOfPolys(), static_cast<vtkIdType>(surface.triangles.size()));
  vtkNew<vtkIdList> ids;
  for (vtkIdType t = 0; t < data->GetNumberOfCells(); ++t) {
    data->GetCellPoints(t, ids);
    ASSERT_EQ(ids->GetNumberOfIds(), 3);
    for (int k = 0; k < 3; ++k) ASSERT_EQ(ids->GetId(k), surface.triangles[t][k]);
  }
  vtkDataArray* normals = data->GetPointData()->GetNormals();
  vtkDataArray* scalars = data->GetPointData()->GetArray("edge_distance_mm");
  ASSERT_NE(normals, nullptr);
  ASSERT_NE(scalars, nullptr);
  for (vtkIdType i = 0; i < data->GetNumberOfPoints(); ++i) {
    double p[3];
    data->GetPoint(i, p);
    for (int a = 0; a < 3; ++a) {
      ASSERT_EQ(p[a], static_cast<double>(static_cast<float>(surface.points(i, a))));
      ASSERT_EQ(normals->GetComponent(i, a), static_cast<double>(static_cast<float>(surface.normals(i, a))));
    }
    ASSERT_EQ(scalars->GetComponent(i, 0), distance[i]);
  }
}

TEST(SurfaceWriter, ObjPlyStlReadBack) {
  const dynsub::TriangleSurface surface = cubeSurface();
  const std::string obj = scratch("cube.obj"), ply = scratch("cube.ply"), stl = scratch("cube.stl");
  for (const std::string& path : {obj, ply, stl}) dynsub::writeTriangleSurface(surface, path);
  // Each triangle's corners where the surface has them, to float: PLY and
  // STL hold floats (as VTK's writers give them), and VTK's OBJ reader reads
  // floats (the OBJ file's numbers read back as the same doubles).
  auto expectTriangles = [&](vtkPolyData* data, const std::string& what) {
    ASSERT_EQ(data->GetNumberOfCells(), static_cast<vtkIdType>(surface.triangles.size())) << what;
    vtkNew<vtkIdList> ids;
    for (vtkIdType t = 0; t < data->GetNumberOfCells(); ++t) {
      data->GetCellPoints(t, ids);
      ASSERT_EQ(ids->GetNumberOfIds(), 3) << what;
      for (int k = 0; k < 3; ++k) {
        double p[3];
        data->GetPoint(ids->GetId(k), p);
        for (int a = 0; a < 3; ++a) {
          const double expected = surface.points(surface.triangles[t][k], a);
          ASSERT_EQ(p[a], static_cast<double>(static_cast<float>(expected)))
              << what << ", triangle " << t << ", corner " << k;
        }
      }
    }
  };
  vtkNew<vtkOBJReader> objReader;
  objReader->SetFileName(obj.c_str());
  objReader->Update();
  expectTriangles(objReader->GetOutput(), "OBJ");
  vtkNew<vtkPLYReader> plyReader;
  plyReader->SetFileName(ply.c_str());
  plyReader->Update();
  EXPECT_EQ(plyReader->GetOutput()->GetNumberOfPoints(), surface.points.rows());
  expectTriangles(plyReader->GetOutput(), "PLY");
  // PLY keeps the points in order, with their normals.
  vtkDataArray* normals = plyReader->GetOutput()->GetPointData()->GetNormals();
  ASSERT_NE(normals, nullptr);
  for (vtkIdType i = 0; i < normals->GetNumberOfTuples(); i += 5)
    for (int a = 0; a < 3; ++a)
      EXPECT_EQ(normals->GetComponent(i, a), static_cast<double>(static_cast<float>(surface.normals(i, a))));
  vtkNew<vtkSTLReader> stlReader;
  stlReader->SetFileName(stl.c_str());
  stlReader->Update();
  expectTriangles(stlReader->GetOutput(), "STL");
}

// 3D Slicer marks a surface's coordinate system ("SPACE=RAS") in a .vtk or
// .stl header or a .ply or .obj comment: a file in RAS is read into LPS, x
// and y negated; one marked LPS, or not at all, as written.
TEST(SurfacePolyData, ReadsSlicersRasSurfacesIntoLps) {
  const dynsub::TriangleSurface surface = cubeSurface();
  const auto expectPoints = [&](const std::string& path, double sx, double sy) {
    SCOPED_TRACE(path);
    const dynsub::MatrixX3 read = dynsub::readSurfacePoints(path);
    ASSERT_EQ(read.rows(), surface.points.rows());
    for (Eigen::Index i = 0; i < read.rows(); ++i) {
      ASSERT_NEAR(read(i, 0), sx * surface.points(i, 0), 1e-6);
      ASSERT_NEAR(read(i, 1), sy * surface.points(i, 1), 1e-6);
      ASSERT_NEAR(read(i, 2), surface.points(i, 2), 1e-6);
    }
  };
  dynsub::writeTriangleSurface(surface, scratch("ras.vtk"), {}, "RAS");
  expectPoints(scratch("ras.vtk"), -1, -1);
  dynsub::writeTriangleSurface(surface, scratch("lps.vtk"), {}, "LPS");
  expectPoints(scratch("lps.vtk"), 1, 1);
  dynsub::writeTriangleSurface(surface, scratch("ras.vtp"), {}, "RAS");  // the field array SPACE
  expectPoints(scratch("ras.vtp"), -1, -1);
  dynsub::writeTriangleSurface(surface, scratch("plain.obj"));
  const std::string objText = [&] {
    std::ifstream in(scratch("plain.obj"));
    return std::string(std::istreambuf_iterator<char>(in), {});
  }();
  { std::ofstream(scratch("ras.obj")) << "# 3D Slicer output. SPACE=RAS\n" << objText; }
  expectPoints(scratch("ras.obj"), -1, -1);
  expectPoints(scratch("plain.obj"), 1, 1);

  const std::string ply =
      "ply\nformat ascii 1.0\ncomment SPACE=RAS\nelement vertex 4\nproperty float x\nproperty float y\n"
      "property float z\nelement face 4\nproperty list uchar int vertex_indices\nend_header\n1 2 3\n4 5 6\n7 8 9\n"
      "1 1 1\n3 0 2 1\n3 0 1 3\n3 1 2 3\n3 0 3 2\n";
  { std::ofstream(scratch("ras.ply")) << ply; }
  EXPECT_EQ(dynsub::readSurfacePoints(scratch("ras.ply")).row(1), Eigen::RowVector3d(-4, -5, 6));
  const std::string stl =
      "solid 3D Slicer output. SPACE=RAS\nfacet normal 0 0 1\nouter loop\nvertex 1 2 3\nvertex 4 5 6\n"
      "vertex 7 8 10\nendloop\nendfacet\nendsolid\n";
  { std::ofstream(scratch("ras.stl")) << stl; }
  EXPECT_EQ(dynsub::readSurfacePoints(scratch("ras.stl")).row(0), Eigen::RowVector3d(-1, -2, 3));
  // Another word ending in SPACE=, or another value, is no mark: as written.
  std::string other = ply;
  other.replace(other.find("SPACE=RAS"), 9, "COLORSPACE=RAS");
  { std::ofstream(scratch("colorspace.ply")) << other; }
  EXPECT_EQ(dynsub::readSurfacePoints(scratch("colorspace.ply")).row(1), Eigen::RowVector3d(4, 5, 6));
}

// readSurfacePolyData reads OBJ with DynSub's own reader: the written
// surface comes back with its exact doubles, and a vertex VTK's OBJ reader
// would take as the origin ("v nan 1 0") is refused with its line.
TEST(SurfacePolyData, ReadsObjExactlyAndRefusesBadRecords) {
  const dynsub::TriangleSurface surface = cubeSurface();
  const std::string obj = scratch("exact.obj");
  dynsub::writeTriangleSurface(surface, obj);
  const vtkSmartPointer<vtkPolyData> read = dynsub::readSurfacePolyData(obj);
  ASSERT_EQ(read->GetNumberOfPoints(), surface.points.rows());
  ASSERT_EQ(read->GetNumberOfPolys(), static_cast<vtkIdType>(surface.triangles.size()));
  for (vtkIdType i = 0; i < read->GetNumberOfPoints(); ++i) {
    double p[3];
    read->GetPoint(i, p);
    for (int a = 0; a < 3; ++a) ASSERT_EQ(p[a], surface.points(i, a)) << "point " << i;
  }
  vtkNew<vtkIdList> ids;
  read->GetCellPoints(7, ids);
  ASSERT_EQ(ids->GetNumberOfIds(), 3);
  for (int k = 0; k < 3; ++k) EXPECT_EQ(ids->GetId(k), surface.triangles[7][k]);

  const std::string tetrahedron = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n";
  auto refused = [&](const std::string& name, const std::string& text) {
    const std::string path = scratch(name);
    { std::ofstream(path) << text; }
    try {
      dynsub::readSurfacePolyData(path);
    } catch (const dynsub::Error& e) {
      return std::string(e.what());
    }
    return std::string("(read without an error)");
  };
  std::string withNan = tetrahedron;
  withNan.replace(withNan.find("v 0 1 0"), 7, "v nan 1 0");
  EXPECT_NE(refused("nan.obj", withNan).find("nan.obj: point 2 has a non-finite coordinate"), std::string::npos)
      << refused("nan.obj", withNan);
  std::string withText = tetrahedron;
  withText.replace(withText.find("v 0 1 0"), 7, "v 0x 1 0");
  EXPECT_NE(refused("text.obj", withText).find("line 3: '0x' is not a number"), std::string::npos);
  EXPECT_NE(refused("range.obj", tetrahedron + "f 1 2 9\n")
                .find("line 9: vertex index 9 is out of range (the file has 4 vertices)"),
            std::string::npos);
  // VTK's readers keep an index past the points; every filter after would
  // read out of bounds.
  const std::string plyTetrahedron =
      "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\n"
      "element face 4\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n"
      "3 0 2 1\n3 0 1 3\n3 1 2 3\n3 0 3 99\n";
  EXPECT_NE(refused("range.ply", plyTetrahedron).find("range.ply: polygon 3 uses point 99, but the file has 4 points"),
            std::string::npos)
      << refused("range.ply", plyTetrahedron);
  const std::string legacy =
      "# vtk DataFile Version 3.0\ntetrahedron\nASCII\nDATASET POLYDATA\nPOINTS 4 float\n0 0 0\n1 0 0\n0 1 0\n"
      "0 0 1\nPOLYGONS 4 16\n3 0 2 1\n3 0 -5 3\n3 1 2 3\n3 0 3 2\n";
  EXPECT_NE(refused("negative.vtk", legacy).find("negative.vtk: polygon 1 uses point -5"), std::string::npos)
      << refused("negative.vtk", legacy);
}

TEST(SurfaceWriter, BadTargetsLeaveNoFile) {
  const dynsub::TriangleSurface surface = cubeSurface();
  EXPECT_THROW(dynsub::writeTriangleSurface(surface, scratch("cube.xyz")), dynsub::Error);
  EXPECT_FALSE(fs::exists(scratch("cube.xyz")));
  EXPECT_THROW(dynsub::writeTriangleSurface(surface, "/nonexistent-dynsub/cube.vtp"), dynsub::Error);
  dynsub::TriangleSurface broken = surface;
  broken.points(3, 1) = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(dynsub::writeTriangleSurface(broken, scratch("nan.vtp")), dynsub::Error);
  EXPECT_FALSE(fs::exists(scratch("nan.vtp")));
}

// A write cut short (here by a file-size limit, as a full disk would) fails
// with one error that names the file and leaves nothing, and VTK's own
// account of it (the writer's error and its pipeline's dump) is not printed.
TEST(SurfaceWriter, AWriteCutShortFailsInOneLine) {
  const dynsub::ControlMesh cube = dynsub::makeCube98();
  const dynsub::LimitSurface limit(cube);
  const dynsub::TriangleSurface surface = dynsub::tessellate(limit, cube.points(), 16);  // about 1 MB as .vtp
  const std::string path = scratch("cut-short.vtp");
  rlimit was{};
  ASSERT_EQ(getrlimit(RLIMIT_FSIZE, &was), 0);
  const auto previousHandler = std::signal(SIGXFSZ, SIG_IGN);  // EFBIG instead of the signal
  rlimit small = was;
  small.rlim_cur = 64 * 1024;
  ASSERT_EQ(setrlimit(RLIMIT_FSIZE, &small), 0);
  testing::internal::CaptureStderr();
  std::string message;
  try {
    dynsub::writeTriangleSurface(surface, path);
  } catch (const dynsub::Error& e) {
    message = e.what();
  }
  const std::string printed = testing::internal::GetCapturedStderr();
  setrlimit(RLIMIT_FSIZE, &was);
  std::signal(SIGXFSZ, previousHandler);
  EXPECT_NE(message.find(path), std::string::npos) << "no error naming the file: '" << message << "'";
  EXPECT_EQ(printed, "");
  EXPECT_FALSE(fs::exists(path));
}

}  // namespace
