// Unit tests: point clouds read by extension, and whether the file was a
// mesh (faces as well as vertices), which decides whether a fit measures the
// points' noise (FitCommand.cpp).
#include <fstream>
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
      EXPECT_EQ(dynsub::readPointCloud(path).meshGenus, genus) << path;
    }
  }
  const std::string tetrahedron = "3 0 2 1\n3 0 1 3\n3 1 2 3\n3 0 3 2\n";
  const std::string twoPieces = writeText(
      "two.off", "OFF\n8 8 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n5 0 0\n6 0 0\n5 1 0\n5 0 1\n" + tetrahedron +
                     "3 4 6 5\n3 4 5 7\n3 5 6 7\n3 4 7 6\n");
  const std::string oneTetrahedron = writeText("one.off", "OFF\n4 4 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n" + tetrahedron);
  // Three triangles on one edge: not a manifold, no genus.
  const std::string fin = writeText("fin.off", "OFF\n5 3 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n0 -1 0\n3 0 1 2\n3 0 1 3\n3 0 1 4\n");
  EXPECT_EQ(dynsub::readPointCloud(oneTetrahedron).meshGenus, 0);
  EXPECT_EQ(dynsub::readPointCloud(twoPieces).meshGenus, -1);
  EXPECT_EQ(dynsub::readPointCloud(fin).meshGenus, -1);
  EXPECT_EQ(dynsub::readPointCloud(writeText("points.xyz", "0 0 0\n1 0 0\n0 1 0\n0 0 1\n")).meshGenus, -1);
}

TEST(PointCloudIO, RefusesUnknownFormats) {
  const std::string path = writeText("cloud.pts", "0 0 0\n");
  EXPECT_THROW(dynsub::readPointCloud(path), dynsub::Error);
}

}  // namespace
