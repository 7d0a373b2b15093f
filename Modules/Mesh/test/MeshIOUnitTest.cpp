// Unit tests (no rendering): every reader gives back the same mesh, and broken
// files are rejected with their name and problem.
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "dynsub/Error.h"
#include "dynsub/MeshIO.h"
#include "dynsub/StandardMeshes.h"

namespace fs = std::filesystem;

namespace {

fs::path scratch(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / "dynsub-meshio";
  fs::create_directories(dir);
  return dir / name;
}

void writeText(const fs::path& path, const std::string& text) { std::ofstream(path) << text; }

void expectError(const std::string& path, const std::string& fragment) {
  try {
    dynsub::readControlMesh(path);
    FAIL() << "no error for " << path;
  } catch (const dynsub::Error& error) {
    const std::string message = error.what();
    EXPECT_NE(message.find(path), std::string::npos) << message;
    EXPECT_NE(message.find(fragment), std::string::npos) << message;
  }
}

TEST(MeshIO, ObjRoundTripIsExact) {
  const dynsub::ControlMesh torus = dynsub::makeTorus32();
  const std::string path = scratch("torus.obj").string();
  dynsub::writeObj(torus, path);
  const dynsub::ControlMesh back = dynsub::readControlMesh(path);
  EXPECT_EQ(back.faces(), torus.faces());
  EXPECT_EQ((back.points() - torus.points()).cwiseAbs().maxCoeff(), 0.0);
}

TEST(MeshIO, ObjAcceptsTextureNormalAndNegativeIndices) {
  const std::string path = scratch("square.obj").string();
  writeText(path, "# square\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvn 0 0 1\nf -4/1/1 2//1 3/3 4\n");
  const dynsub::ControlMesh mesh = dynsub::readControlMesh(path);
  EXPECT_EQ(mesh.faces(), (std::vector<dynsub::Polygon>{{0, 1, 2, 3}}));
}

TEST(MeshIO, OffAndAsciiPlyReadTheSameMesh) {
  const std::string off = scratch("tri.off").string();
  writeText(off, "OFF\n# comment\n4 2 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n3 0 1 2\n3 0 2 3\n");
  const std::string ply = scratch("tri.ply").string();
  writeText(ply,
            "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\n"
            "element face 2\nproperty list uchar int vertex_indices\nend_header\n"
            "0 0 0\n1 0 0\n1 1 0\n0 1 0\n3 0 1 2\n3 0 2 3\n");
  const dynsub::ControlMesh a = dynsub::readControlMesh(off);
  const dynsub::ControlMesh b = dynsub::readControlMesh(ply);
  EXPECT_EQ(a.faces(), b.faces());
  EXPECT_EQ(a.points(), b.points());
}

// COFF (CGAL's and Geomview's per-vertex and per-face colours) reads as
// the plain OFF; a 4D OFF is refused by name.
TEST(MeshIO, ColouredOffReadsAsOff) {
  const std::string coff = scratch("tri.coff.off").string();
  writeText(coff, "COFF\n4 2 0\n0 0 0 192 192 192 255\n1 0 0 1 2 3 4\n1 1 0 0 0 0 0\n0 1 0 9 9 9 9\n"
                  "3 0 1 2 255 0 0\n3 0 2 3\n");
  const std::string off = scratch("tri.plain.off").string();
  writeText(off, "OFF\n4 2 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n3 0 1 2\n3 0 2 3\n");
  const dynsub::ControlMesh a = dynsub::readControlMesh(coff);
  const dynsub::ControlMesh b = dynsub::readControlMesh(off);
  EXPECT_EQ(a.faces(), b.faces());
  EXPECT_EQ(a.points(), b.points());
  const std::string fourD = scratch("tri.4off.off").string();
  writeText(fourD, "4OFF\n4 2 0\n0 0 0 1\n1 0 0 1\n1 1 0 1\n0 1 0 1\n3 0 1 2\n3 0 2 3\n");
  expectError(fourD, "found '4OFF'");
}

TEST(MeshIO, BinaryPlyInBothByteOrders) {
  for (const std::string order : {"binary_little_endian", "binary_big_endian"}) {
    const std::string path = scratch("quad-" + order + ".ply").string();
    std::ofstream out(path, std::ios::binary);
    out << "ply\nformat " << order << " 1.0\nelement vertex 4\nproperty double x\nproperty double y\n"
        << "property double z\nproperty uchar red\nelement face 1\nproperty list uchar int vertex_indices\n"
        << "end_header\n";
    const bool swap = order == "binary_big_endian";
    auto put = [&out, swap](auto value) {
      char bytes[sizeof(value)];
      std::memcpy(bytes, &value, sizeof(value));
      if (swap) std::reverse(bytes, bytes + sizeof(value));
      out.write(bytes, sizeof(value));
    };
    const double xy[4][2] = {{0, 0}, {2, 0}, {2, 2}, {0, 2}};
    for (const auto& p : xy) {
      put(p[0]);
      put(p[1]);
      put(0.5);
      put(std::uint8_t{255});
    }
    put(std::uint8_t{4});
    for (std::int32_t v : {0, 1, 2, 3}) put(v);
    out.close();
    const dynsub::ControlMesh mesh = dynsub::readControlMesh(path);
    EXPECT_EQ(mesh.vertexCount(), 4) << order;
    EXPECT_EQ(mesh.points()(2, 0), 2.0) << order;
    EXPECT_EQ(mesh.points()(3, 2), 0.5) << order;
  }
}

TEST(MeshIO, BrokenFilesAreNamed) {
  expectError(scratch("missing.obj").string(), "no such file");
  const std::string unknown = scratch("mesh.stl").string();
  writeText(unknown, "solid");
  expectError(unknown, "unknown mesh format");
  const std::string badNumber = scratch("bad.obj").string();
  writeText(badNumber, "v 0 0 0\nv 1 x 0\n");
  expectError(badNumber, "line 2");
  // An OBJ index past the last vertex is named at its line, as written (from 1).
  const std::string pastLast = scratch("past_last.obj").string();
  writeText(pastLast, "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 2 3\nf 1 3 4\nf 1 4 2\nf 2 4 7\n");
  expectError(pastLast, "line 8: vertex index 7 is out of range (the file has 4 vertices)");
  // The mesh checks count as the file does: from 1 in an OBJ (its 5th vertex,
  // its 4th face), from 0 in an OFF.
  const std::string isolated = scratch("isolated.obj").string();
  writeText(isolated, "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nv 5 5 5\nf 1 2 3\nf 1 3 4\nf 1 4 2\nf 2 4 3\n");
  expectError(isolated, "vertex 5 is isolated");
  const std::string repeated = scratch("repeated.obj").string();
  writeText(repeated, "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 2 3\nf 1 3 4\nf 1 4 2\nf 2 4 4\n");
  expectError(repeated, "face 4 is degenerate: it uses vertex 4 twice");
  const std::string isolatedOff = scratch("isolated.off").string();
  writeText(isolatedOff, "OFF\n5 4 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n5 5 5\n3 0 1 2\n3 0 2 3\n3 0 3 1\n3 1 3 2\n");
  expectError(isolatedOff, "vertex 4 is isolated");
  const std::string truncated = scratch("truncated.off").string();
  writeText(truncated, "OFF\n4 1 0\n0 0 0\n1 0 0\n");
  expectError(truncated, "truncated");
  // A face past the header's count would be dropped unseen.
  const std::string extra = scratch("extra.off").string();
  writeText(extra, "OFF\n4 1 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 1 2\n3 0 1 3\n");
  expectError(extra, "line 8: more records than the 4 vertices and 1 faces");
  const std::string directory = scratch("folder.obj").string();
  std::filesystem::create_directories(directory);
  expectError(directory, "is a directory");
  const std::string truncatedPly = scratch("truncated.ply").string();
  writeText(truncatedPly, "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\n"
                          "property float y\nproperty float z\nend_header\n\x01\x02");
  expectError(truncatedPly, "truncated");
  // Likewise in PLY, ASCII or binary (a trailing newline is no record).
  const std::string plyHeader =
      "element vertex 4\nproperty float x\nproperty float y\nproperty float z\n"
      "element face 1\nproperty list uchar int vertex_indices\nend_header\n";
  const std::string extraPly = scratch("extra.ply").string();
  writeText(extraPly, "ply\nformat ascii 1.0\n" + plyHeader + "0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 1 2\n3 0 1 3\n");
  expectError(extraPly, "goes on after the elements its PLY header announces (4 vertex, 1 face)");
  std::string binary = "ply\nformat binary_little_endian 1.0\n" + plyHeader;
  const float corners[12] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1};
  binary.append(reinterpret_cast<const char*>(corners), sizeof corners);
  const auto face = [&binary](std::int32_t a, std::int32_t b, std::int32_t c) {
    binary += '\x03';
    for (const std::int32_t v : {a, b, c}) binary.append(reinterpret_cast<const char*>(&v), sizeof v);
  };
  face(0, 1, 2);
  const std::string oneFace = scratch("one_face.ply").string();
  writeText(oneFace, binary + "\n");
  EXPECT_EQ(dynsub::readPolygonData(oneFace).faces.size(), 1u);
  face(0, 1, 3);
  const std::string extraBinary = scratch("extra_binary.ply").string();
  writeText(extraBinary, binary);
  expectError(extraBinary, "goes on after the elements");
  const std::string empty = scratch("empty.obj").string();
  writeText(empty, "");
  expectError(empty, "no vertices");
}

// OpenSubdiv's crease tags: vertices numbered from 0, one edge per tag.
constexpr const char* kCreasedSquares =
    "v 0 0 0\nv 1 0 0\nv 2 0 0\nv 0 1 0\nv 1 1 0\nv 2 1 0\nv 0 2 0\nv 1 2 0\nv 2 2 0\n"
    "f 1 2 5 4\nf 2 3 6 5\nf 4 5 8 7\nf 5 6 9 8\n";

TEST(MeshIO, CreaseTagsRoundTrip) {
  const std::string path = scratch("creased.obj").string();
  // A sharp crease across the grid, boundary to boundary, and a semi-sharp one.
  writeText(path,
            std::string(kCreasedSquares) + "t crease 2/1/0 3 4 10\nt crease 2/1/0 4 5 10\nt crease 2/1/0 1 4 1.5\n");
  const dynsub::ControlMesh mesh = dynsub::readControlMesh(path);
  const dynsub::Topology& topology = mesh.topology();
  EXPECT_EQ(topology.edgeSharpness(topology.findEdge(3, 4)), 10.0);
  EXPECT_EQ(topology.edgeSharpness(topology.findEdge(4, 5)), 10.0);
  EXPECT_EQ(topology.edgeSharpness(topology.findEdge(1, 4)), 1.5);
  EXPECT_EQ(topology.edgeSharpness(topology.findEdge(4, 7)), 0.0);
  ASSERT_EQ(mesh.creases().size(), 3u);

  const std::string copy = scratch("creased-copy.obj").string();
  dynsub::writeObj(mesh, copy);
  const dynsub::ControlMesh again = dynsub::readControlMesh(copy);
  for (int e = 0; e < topology.edgeCount(); ++e) {
    const auto [a, b] = topology.edgeVertices(e);
    EXPECT_EQ(again.topology().edgeSharpness(again.topology().findEdge(a, b)), topology.edgeSharpness(e));
  }
}

TEST(MeshIO, BadCreaseTagsAreNamed) {
  const std::string square = std::string(kCreasedSquares);
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"t corner 1/1/0 4 2.0\n", "'corner' is not supported"},
      {"t crease 2/1/0 4 5\n", "must read 't crease 2/1/0 a b sharpness'"},
      {"t crease 2/1/0 0 4 1\n", "crease (0, 4) is not an edge"},
      {"t crease 2/1/0 4 9 1\n", "crease (4, 9) is not an edge"},
      {"t crease 2/1/0 4 5 -1\n", "has sharpness -1"},
      {"t crease 2/1/0 4 5 nan\n", "has sharpness nan"},
      {"t crease 2/1/0 5 4 5\n", "crease (4, 5) has sharpness 5.000000: semi-sharp creases up to 4"},
      // Crease tags count vertices from 0, where the OBJ's other messages count from 1: said where it matters.
      {"t crease 2/1/0 3 4 10\n",
       "vertex 4 (counted from 0, as crease tags count): a sharp crease ends inside the "
       "surface (a dart)"},
      {"t crease 2/1/0 4 5 1\nt crease 2/1/0 5 4 2\n", "crease (5, 4) is tagged twice, with sharpness 1 and 2"},
      // Two sharp creases at the centre with one face between them.
      {"t crease 2/1/0 1 4 10\nt crease 2/1/0 4 5 10\n", "single face on one side"},
  };
  for (size_t k = 0; k < cases.size(); ++k) {
    const std::string path = scratch("badcrease" + std::to_string(k) + ".obj").string();
    writeText(path, square + cases[k].first);
    expectError(path, cases[k].second);
  }
}

TEST(MeshIO, FailedWriteLeavesNoFile) {
  EXPECT_THROW(dynsub::writeObj(dynsub::makeCube98(), "/nonexistent-dynsub/cube.obj"), dynsub::Error);
  // OBJ text under another format's name would be misread as that format.
  const std::string off = scratch("cube.off").string();
  try {
    dynsub::writeObj(dynsub::makeCube98(), off);
    ADD_FAILURE() << "an .off name was written";
  } catch (const dynsub::Error& e) {
    EXPECT_NE(std::string(e.what()).find(off + ": the control mesh is written as OBJ"), std::string::npos) << e.what();
  }
  EXPECT_FALSE(std::filesystem::exists(off));
  EXPECT_FALSE(fs::exists("/nonexistent-dynsub/cube.obj"));
}

}  // namespace
