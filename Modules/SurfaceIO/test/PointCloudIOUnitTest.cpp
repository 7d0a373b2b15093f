// Unit tests: point clouds read by extension, whether the file was a mesh
// (faces as well as vertices), which decides whether a fit measures the
// points' noise, and the genus of a closed mesh, which a fit checks its
// model against (FitCommand.cpp).
#include <array>
#include <cmath>
#include <fstream>
#include <iterator>
#include <sstream>
#include <string>
#include <utility>

#include <gtest/gtest.h>

#include "ScratchFiles.h"
#include "dynsub/Error.h"
#include "dynsub/PointCloudIO.h"
#include "dynsub/StandardMeshes.h"
#include "dynsub/SurfaceWriter.h"

namespace {

std::string scratch(const std::string& name) { return dynsub::scratchFile("pointcloudio", name).string(); }

std::string writeText(const std::string& name, const std::string& text) {
  const std::string path = scratch(name);
  std::ofstream(path) << text;
  return path;
}

TEST(PointCloudIO, SurfaceFilesAreMeshVertices) {
  const dynsub::ControlMesh cube = dynsub::makeCube98();
  const dynsub::LimitSurface limit(cube);
  const dynsub::TriangleSurface surface = dynsub::tessellate(limit, cube.points(), 2);
  for (const std::string extension : {".vtp", ".obj", ".ply", ".off"}) {
    const std::string path = scratch("cube" + extension);
    if (extension == ".off") {
      std::ofstream off(path);
      off << "OFF\n" << surface.points.rows() << ' ' << surface.triangles.size() << " 0\n";
      for (Eigen::Index i = 0; i < surface.points.rows(); ++i)
        off << surface.points(i, 0) << ' ' << surface.points(i, 1) << ' ' << surface.points(i, 2) << '\n';
      for (const auto& t : surface.triangles) off << "3 " << t[0] << ' ' << t[1] << ' ' << t[2] << '\n';
    } else {
      dynsub::writeTriangleSurface(surface, path);
    }
    const dynsub::PointCloud cloud = dynsub::readPointCloud(path);
    EXPECT_EQ(cloud.points.rows(), surface.points.rows()) << extension;
    EXPECT_TRUE(cloud.meshVertices) << extension;
  }
}

// A .ply, .obj or .vtp that 3D Slicer marked "SPACE=RAS" (a comment, the
// field array SPACE) is read into LPS, x and y negated, and says so; a file
// marked LPS, or not at all, is read as written. The PLY is DynSub's binary
// one with the comment put in its header.
TEST(PointCloudIO, SlicersRasFilesAreReadIntoLps) {
  const dynsub::ControlMesh cube = dynsub::makeCube98();
  const dynsub::TriangleSurface surface = dynsub::tessellate(dynsub::LimitSurface(cube), cube.points(), 1);
  const auto expectPoints = [&](const std::string& path, const std::string& space, double sign) {
    SCOPED_TRACE(path);
    const dynsub::PointCloud cloud = dynsub::readPointCloud(path);
    EXPECT_EQ(cloud.space, space);
    ASSERT_EQ(cloud.points.rows(), surface.points.rows());
    // PLY holds floats: 1e-6 mm is float's rounding on this unit cube.
    for (Eigen::Index i = 0; i < cloud.points.rows(); ++i)
      ASSERT_LT((cloud.points.row(i) - surface.points.row(i).cwiseProduct(Eigen::RowVector3d(sign, sign, 1))).norm(),
                1e-6);
  };
  const auto marked = [&](const std::string& extension, const std::string& after, const std::string& mark) {
    const std::string plain = scratch("plain" + extension);
    dynsub::writeTriangleSurface(surface, plain);
    std::ifstream in(plain, std::ios::binary);
    std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    const std::size_t at = after.empty() ? 0 : bytes.find(after) + after.size();
    bytes.insert(at, mark);
    const std::string path = scratch("marked" + extension);
    std::ofstream(path, std::ios::binary) << bytes;
    return path;
  };
  expectPoints(marked(".ply", "\n", "comment 3D Slicer SPACE=RAS\r\n"), "RAS", -1);
  expectPoints(marked(".ply", "\n", "comment\tSPACE=RAS\n"), "RAS", -1);
  expectPoints(marked(".ply", "\n", "comment SPACE=LPS\n"), "LPS", 1);
  expectPoints(marked(".ply", "\n", "comment COLORSPACE=RAS SPACE=RAS_2\n"), "", 1);  // no mark
  expectPoints(marked(".obj", "", "# SPACE=RAS\n"), "RAS", -1);
  expectPoints(scratch("plain.obj"), "", 1);
  // An OBJ's mark is among the comments it begins with, not after its data.
  const dynsub::PointCloud late = dynsub::readPointCloud(
      writeText("late.obj", "v 1 2 3\n# SPACE=RAS\nv 4 5 6\nv 7 8 10\nv 1 1 1\nf 1 2 3\nf 1 3 4\n"));
  EXPECT_EQ(late.space, "");
  EXPECT_EQ(late.points.row(0), Eigen::RowVector3d(1, 2, 3));
  dynsub::writeTriangleSurface(surface, scratch("ras.vtp"), {}, "RAS");
  expectPoints(scratch("ras.vtp"), "RAS", -1);
  dynsub::writeTriangleSurface(surface, scratch("plain.vtp"));
  expectPoints(scratch("plain.vtp"), "", 1);
}

// A .vtp cut short: one error that names the file and VTK's reason, and
// nothing of VTK's own log on stderr (its XML parser's line, an executive's
// dump).
TEST(PointCloudIO, ATruncatedVtpIsRefusedInOneMessage) {
  const dynsub::ControlMesh cube = dynsub::makeCube98();
  const dynsub::LimitSurface limit(cube);
  const std::string whole = scratch("whole.vtp");
  dynsub::writeTriangleSurface(dynsub::tessellate(limit, cube.points(), 2), whole);
  std::ifstream in(whole, std::ios::binary);
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const std::string cut = writeText("cut.vtp", text.substr(0, text.size() / 2));
  testing::internal::CaptureStderr();
  std::string error;
  try {
    dynsub::readPointCloud(cut);
  } catch (const dynsub::Error& e) {
    error = e.what();
  }
  const std::string printed = testing::internal::GetCapturedStderr();
  EXPECT_NE(error.find("cut.vtp: VTK could not read the points: "), std::string::npos) << error;
  EXPECT_EQ(error.find("0x"), std::string::npos) << error;
  EXPECT_EQ(printed, "");
}

TEST(PointCloudIO, PointFilesAreNotMeshVertices) {
  const std::string points = "0 0 0\n1 0 0\n0 1 0\n0 0 1\n1 1 1\n";
  const std::string paths[] = {
      writeText("cloud.xyz", points),
      writeText("cloud.csv", "x,y,z\n0,0,0\n1,0,0\n0,1,0\n0,0,1\n1,1,1\n"),
      writeText("cloud.off", "OFF\n5 0 0\n" + points),
      writeText("cloud.ply",
                "ply\nformat ascii 1.0\nelement vertex 5\nproperty float x\nproperty float y\n"
                "property float z\nend_header\n" + points),
  };
  for (const std::string& path : paths) {
    const dynsub::PointCloud cloud = dynsub::readPointCloud(path);
    EXPECT_EQ(cloud.points.rows(), 5) << path;
    EXPECT_FALSE(cloud.meshVertices) << path;
  }
}

// A CSV's header names its columns: the coordinates are read from the
// columns it names x, y and z (or l, p and s, as 3D Slicer exports points),
// wherever they are (pandas writes an index column first); three columns
// without those names are x, y, z in order. More columns without them, an
// axis named twice, and a row longer than the header are refused rather
// than read with the values shifted.
TEST(PointCloudIO, ACsvHeaderNamesTheCoordinatesColumns) {
  const dynsub::MatrixX3 indexed =
      dynsub::readPointCloud(writeText("pandas.csv", ",x,y,z\n0,1,2,3\n1,4,5,6\n2,7,8,9\n3,1,1,2\n")).points;
  ASSERT_EQ(indexed.rows(), 4);
  EXPECT_EQ(indexed.row(1), Eigen::RowVector3d(4, 5, 6));
  const dynsub::MatrixX3 reordered =
      dynsub::readPointCloud(writeText("zyx.csv", "\"Z\";\"Y\";\"X\"\n3;2;1\n6;5;4\n9;8;7\n2;1;1\n")).points;
  EXPECT_EQ(reordered.row(0), Eigen::RowVector3d(1, 2, 3));
  const dynsub::MatrixX3 unnamed =
      dynsub::readPointCloud(writeText("abc.csv", "a,b,c\n1,2,3\n4,5,6\n7,8,9\n1,1,2\n")).points;
  EXPECT_EQ(unnamed.row(0), Eigen::RowVector3d(1, 2, 3));
  // Names with units, Excel's byte order mark, CloudCompare's "//".
  for (const std::string header : {"x_mm,y_mm,z_mm,label", "\xEF\xBB\xBFX [mm],Y [mm],Z [mm],label", "//X,Y,Z,R"}) {
    const dynsub::MatrixX3 named =
        dynsub::readPointCloud(writeText("named.csv", header + "\n1,2,3,9\n4,5,6,9\n7,8,9,9\n1,1,2,9\n")).points;
    EXPECT_EQ(named.row(0), Eigen::RowVector3d(1, 2, 3)) << header;
  }
  const dynsub::MatrixX3 blanks =
      dynsub::readPointCloud(writeText("blanks.csv", "x y z\n1 2 3\n4 5 6\n7 8 9\n1 1 2\n")).points;
  EXPECT_EQ(blanks.row(3), Eigen::RowVector3d(1, 1, 2));
  const dynsub::MatrixX3 slicer =
      dynsub::readPointCloud(
          writeText("slicer.csv", "label,l,p,s,defined\nF-1,1,2,3,1\nF-2,4,5,6,1\nF-3,7,8,9,1\nF-4,1,1,2,1\n"))
          .points;
  EXPECT_EQ(slicer.row(1), Eigen::RowVector3d(4, 5, 6));
  // Of two columns of an axis, the one in mm; a quoted label with a comma
  // and a separator ending a row add no column.
  const dynsub::MatrixX3 inMm =
      dynsub::readPointCloud(
          writeText("units.csv",
                    "x_vox,y_vox,z_vox,x_mm,y_mm,z_mm\n9,9,9,1,2,3\n9,9,9,4,5,6\n9,9,9,7,8,9\n9,9,9,1,1,2\n"))
          .points;
  EXPECT_EQ(inMm.row(0), Eigen::RowVector3d(1, 2, 3));
  const dynsub::MatrixX3 quoted =
      dynsub::readPointCloud(
          writeText("quoted.csv", "x,y,z,label\n1,2,3,\"left, anterior\"\n4,5,6,b\n7,8,9,\n1,1,2,\n"))
          .points;
  ASSERT_EQ(quoted.rows(), 4);
  EXPECT_EQ(quoted.row(3), Eigen::RowVector3d(1, 1, 2));
  const std::pair<std::string, std::string> refused[] = {
      {"id,px,py,pz\n0,1,2,3\n1,4,5,6\n2,7,8,9\n3,1,1,2\n",
       "line 1: the header names no columns x, y and z among its 4"},
      {"label,r,a,s\n1,1,2,3\n2,4,5,6\n3,7,8,9\n4,1,1,2\n", "line 1: the columns r, a and s are RAS coordinates"},
      {"r,a,s\n1,2,3\n4,5,6\n7,8,9\n1,1,2\n", "line 1: the columns r, a and s are RAS coordinates"},
      {"x,y,w\n1,2,3\n4,5,6\n7,8,9\n1,1,2\n", "line 1: the header does not name all the coordinates' columns"},
      {"x,y,z,x\n1,2,3,4\n4,5,6,7\n7,8,9,1\n1,1,2,1\n", "line 1: the header names 2 columns x"},
      {"x,y,z\n1,2,3\n4,5,6,7\n7,8,9\n1,1,2\n", "line 3: 4 values, where the header names 3"},
  };
  for (const auto& [text, message] : refused) {
    try {
      dynsub::readPointCloud(writeText("refused.csv", text));
      FAIL() << text << " was read";
    } catch (const dynsub::Error& e) {
      EXPECT_NE(std::string(e.what()).find("refused.csv: " + message), std::string::npos) << e.what();
    }
  }
  // Without a header, the first point sets the row's width.
  try {
    dynsub::readPointCloud(writeText("rows.xyz", "1 2 3\n4 5 6\n7 8 9 1\n1 1 2\n"));
    FAIL() << "a row of four values was read";
  } catch (const dynsub::Error& e) {
    EXPECT_NE(std::string(e.what()).find("rows.xyz: line 3: 4 values, where the first point has 3"), std::string::npos)
        << e.what();
  }
}

int genusOf(const std::string& path) { return dynsub::closedMeshGenus(dynsub::readPointCloud(path), path); }

// A fit warns when its model's genus is not the scan's (FitCommand.cpp), so
// the genus is given only where it is defined: one closed manifold piece.
TEST(PointCloudIO, ClosedMeshesGiveTheirGenus) {
  const std::pair<dynsub::ControlMesh, int> cases[] = {
      {dynsub::makeCube98(), 0}, {dynsub::makeTorus32(), 1}, {dynsub::makeSheet81(), -1}};
  for (const auto& [mesh, genus] : cases) {
    const dynsub::LimitSurface limit(mesh);
    const dynsub::TriangleSurface surface = dynsub::tessellate(limit, mesh.points(), 2);
    for (const std::string extension : {".vtp", ".obj", ".ply"}) {
      const std::string path = scratch("genus" + std::to_string(genus) + extension);
      dynsub::writeTriangleSurface(surface, path);
      EXPECT_EQ(genusOf(path), genus) << path;
    }
  }
  const std::string tetrahedron = "0 0 0\n1 0 0\n0 1 0\n0 0 1\n";
  const std::string tetrahedronFaces = "3 0 2 1\n3 0 1 3\n3 1 2 3\n3 0 3 2\n";
  EXPECT_EQ(genusOf(writeText("one.off", "OFF\n4 4 0\n" + tetrahedron + tetrahedronFaces)), 0);
  // A point no face uses (exported files have them) does not hide the genus.
  EXPECT_EQ(genusOf(writeText("spare.off", "OFF\n5 4 0\n" + tetrahedron + "9 9 9\n" + tetrahedronFaces)), 0);
  // A tetrahedron beside a torus: Euler characteristic 2 + 0, which one
  // piece of genus 0 would have too.
  const dynsub::ControlMesh torus = dynsub::makeTorus32();
  std::ostringstream twoPieces;
  twoPieces << "OFF\n" << torus.vertexCount() + 4 << ' ' << torus.faceCount() + 4 << " 0\n";
  for (Eigen::Index v = 0; v < torus.vertexCount(); ++v)
    twoPieces << torus.points()(v, 0) << ' ' << torus.points()(v, 1) << ' ' << torus.points()(v, 2) << '\n';
  twoPieces << "100 0 0\n101 0 0\n100 1 0\n100 0 1\n";
  for (const dynsub::Polygon& face : torus.faces()) {
    twoPieces << face.size();
    for (int v : face) twoPieces << ' ' << v;
    twoPieces << '\n';
  }
  const int t = torus.vertexCount();
  for (const auto& f : {std::array<int, 3>{0, 2, 1}, {0, 1, 3}, {1, 2, 3}, {0, 3, 2}})
    twoPieces << "3 " << t + f[0] << ' ' << t + f[1] << ' ' << t + f[2] << '\n';
  EXPECT_EQ(genusOf(writeText("two.off", twoPieces.str())), -1);
  // Three triangles on one edge: not a manifold, no genus.
  EXPECT_EQ(genusOf(writeText("fin.off", "OFF\n5 3 0\n" + tetrahedron + "0 -1 0\n3 0 1 2\n3 0 1 3\n3 0 1 4\n")), -1);
  EXPECT_EQ(genusOf(writeText("points.xyz", tetrahedron)), -1);
}

// Points written as .xyz read back as the very same doubles, awkward ones
// included (thirds, tiny and huge magnitudes, negative zero): a fit's
// outliers.xyz is matched row for row against the scan it came from.
TEST(PointCloudIO, XyzRoundTripIsExact) {
  dynsub::MatrixX3 points(4, 3);
  points << 1.0 / 3.0, -2.0 / 7.0, 1e-300, 123456.789012345678, -0.0, 5e307, 0.1, 0.2, 0.3, -1.0 / 3.0,
      2.0 / 3.0, 1e-17;
  const std::string path = scratch("roundtrip.xyz");
  dynsub::writePointCloudXyz(points, path);
  const dynsub::PointCloud read = dynsub::readPointCloud(path);
  ASSERT_EQ(read.points.rows(), points.rows());
  for (Eigen::Index p = 0; p < points.rows(); ++p)
    for (int c = 0; c < 3; ++c) {
      EXPECT_EQ(read.points(p, c), points(p, c)) << "point " << p << ", column " << c;
      EXPECT_EQ(std::signbit(read.points(p, c)), std::signbit(points(p, c))) << "point " << p << ", column " << c;
    }
  EXPECT_FALSE(read.meshVertices);
  EXPECT_THROW(dynsub::writePointCloudXyz(points, scratch("no/such/dir/x.xyz")), dynsub::Error);
}

TEST(PointCloudIO, RefusesUnknownFormats) {
  const std::string path = writeText("cloud.pts", "0 0 0\n");
  EXPECT_THROW(dynsub::readPointCloud(path), dynsub::Error);
}

TEST(PointCloudIO, RefusesPolygonsNamingPointsItHasNot) {
  const std::string path = writeText("overshoot.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 9\n");
  try {
    dynsub::readPointCloud(path);
    FAIL() << "read a triangle naming point 9 of 3";
  } catch (const dynsub::Error& e) {
    EXPECT_NE(std::string(e.what()).find("overshoot.off: a polygon names point 9 of 3"), std::string::npos) << e.what();
  }
}

}  // namespace
