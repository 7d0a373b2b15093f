// Unit tests (no rendering): the papers' initial meshes have the stated counts,
// topology and orientation, and the copies in Data/Meshes are identical.
#include <gtest/gtest.h>

#include <algorithm>

#include "dynsub/Error.h"
#include "dynsub/MeshIO.h"
#include "dynsub/StandardMeshes.h"

namespace {

int countValence(const dynsub::ControlMesh& mesh, int valence) {
  int count = 0;
  for (int v = 0; v < mesh.vertexCount(); ++v)
    count += static_cast<int>(mesh.topology().vertexEdges(v).size()) == valence;
  return count;
}

TEST(StandardMeshes, CubeHasThePapersCounts) {
  const dynsub::ControlMesh cube = dynsub::makeCube98();
  EXPECT_EQ(cube.vertexCount(), 98);
  EXPECT_EQ(cube.faceCount(), 96);
  EXPECT_EQ(countValence(cube, 3), 8);
  EXPECT_EQ(countValence(cube, 4), 90);
  EXPECT_TRUE(cube.isClosed());
  EXPECT_EQ(cube.genus(), 0);
  EXPECT_NEAR(dynsub::enclosedVolume(cube), 8.0, 1e-12);
}

TEST(StandardMeshes, TorusAndSheet) {
  const dynsub::ControlMesh torus = dynsub::makeTorus32();
  EXPECT_EQ(torus.vertexCount(), 32);
  EXPECT_EQ(torus.faceCount(), 32);
  EXPECT_EQ(torus.genus(), 1);
  EXPECT_GT(dynsub::enclosedVolume(torus), 0.0);
  const dynsub::ControlMesh sheet = dynsub::makeSheet81();
  EXPECT_EQ(sheet.vertexCount(), 81);
  EXPECT_EQ(sheet.faceCount(), 64);
  EXPECT_EQ(sheet.boundaryLoopCount(), 1);
  EXPECT_EQ(countValence(sheet, 2), 4);
}

// A mesh whose faces all turn inward encloses a negative volume, and is
// refused as an initial model, naming its file.
TEST(StandardMeshes, AMeshFacingInwardIsRefused) {
  const dynsub::ControlMesh cube = dynsub::makeCube98();
  std::vector<dynsub::Polygon> reversed = cube.faces();
  for (dynsub::Polygon& face : reversed) std::reverse(face.begin(), face.end());
  const dynsub::ControlMesh inward = dynsub::ControlMesh::fromPolygons(cube.points(), reversed);
  EXPECT_NEAR(dynsub::enclosedVolume(inward), -8.0, 1e-12);
  EXPECT_NO_THROW(dynsub::requireOutwardFacing(cube, "cube.obj"));
  try {
    dynsub::requireOutwardFacing(inward, "inward.obj");
    FAIL() << "a mesh facing inward was taken";
  } catch (const dynsub::Error& e) {
    EXPECT_NE(std::string(e.what()).find("inward.obj: the control mesh faces inward"), std::string::npos) << e.what();
  }
}

// A cube and a torus side by side: two pieces whose genera add up (the Euler
// characteristic alone, taken as one piece's, gave -1 for two cubes).
TEST(StandardMeshes, PiecesCountedAndTheirGeneraAdded) {
  const dynsub::ControlMesh cube = dynsub::makeCube98(), torus = dynsub::makeTorus32();
  std::vector<dynsub::Polygon> faces = cube.faces();
  for (dynsub::Polygon face : torus.faces()) {
    for (int& v : face) v += cube.vertexCount();
    faces.push_back(face);
  }
  dynsub::MatrixX3 points(cube.vertexCount() + torus.vertexCount(), 3);
  points << cube.points(), torus.points().rowwise() + Eigen::RowVector3d(10, 0, 0);
  const dynsub::ControlMesh both = dynsub::ControlMesh::fromPolygons(points, faces, "cube and torus");
  EXPECT_EQ(cube.pieceCount(), 1);
  EXPECT_EQ(both.pieceCount(), 2);
  EXPECT_EQ(both.genus(), 1);
  EXPECT_TRUE(both.isClosed());
}

TEST(StandardMeshes, DataFilesMatchTheConstructedMeshes) {
  for (const std::string& name : dynsub::standardMeshNames()) {
    const dynsub::ControlMesh built = dynsub::makeStandardMesh(name);
    const dynsub::ControlMesh stored =
        dynsub::readControlMesh(std::string(DYNSUB_DATA_DIR) + "/Meshes/" + name + ".obj");
    EXPECT_EQ(stored.faces(), built.faces()) << name;
    EXPECT_EQ(stored.points(), built.points()) << name;
  }
}

}  // namespace
