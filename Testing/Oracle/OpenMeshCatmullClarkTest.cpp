// One Catmull-Clark step against OpenMesh's CatmullClarkT, a second
// independent oracle beside OpenSubdiv: on closed meshes of quads, triangles
// and pentagons, of genus 0, 1 and 2, both give the same refined points and
// the same faces, each face with the same vertices in the same order.
// (CatmullClarkT leaves boundaries to its caller, so only closed meshes are
// compared.)
#include <algorithm>
#include <map>
#include <set>

#include <OpenMesh/Core/Mesh/PolyMesh_ArrayKernelT.hh>
#include <OpenMesh/Tools/Subdivider/Uniform/CatmullClarkT.hh>
#include <gtest/gtest.h>

#include "dynsub/CatmullClark.h"
#include "dynsub/MeshIO.h"
#include "dynsub/StandardMeshes.h"

namespace dynsub {
namespace {

struct DoubleTraits : OpenMesh::DefaultTraits {
  typedef OpenMesh::Vec3d Point;
  typedef OpenMesh::Vec3d Normal;
};
using OpenMeshPoly = OpenMesh::PolyMesh_ArrayKernelT<DoubleTraits>;

// The faces as sequences of points, each started at its smallest point so
// that the same cycle in the same order compares equal.
using Face = std::vector<std::array<double, 3>>;
Face canonical(Face face) {
  std::rotate(face.begin(), std::min_element(face.begin(), face.end()), face.end());
  return face;
}

// Each point rounded to a grid far finer than the meshes' features and far
// coarser than rounding error, so that both refinements' points compare
// as keys.
std::array<double, 3> key(double x, double y, double z) {
  const auto round = [](double v) { return std::round(v * 1e9) / 1e9; };
  return {round(x), round(y), round(z)};
}

std::set<Face> ourRefinement(const ControlMesh& mesh) {
  const ControlMesh refined = subdivide(mesh).mesh;
  const MatrixX3& p = refined.points();
  std::set<Face> faces;
  for (const Polygon& polygon : refined.topology().faces()) {
    Face face;
    for (int v : polygon) face.push_back(key(p(v, 0), p(v, 1), p(v, 2)));
    faces.insert(canonical(face));
  }
  return faces;
}

std::set<Face> openMeshRefinement(const ControlMesh& mesh) {
  OpenMeshPoly om;
  std::vector<OpenMeshPoly::VertexHandle> vertices;
  const MatrixX3& p = mesh.points();
  for (int v = 0; v < mesh.vertexCount(); ++v) vertices.push_back(om.add_vertex({p(v, 0), p(v, 1), p(v, 2)}));
  for (const Polygon& polygon : mesh.topology().faces()) {
    std::vector<OpenMeshPoly::VertexHandle> face;
    for (int v : polygon) face.push_back(vertices[v]);
    EXPECT_TRUE(om.add_face(face).is_valid());
  }
  OpenMesh::Subdivider::Uniform::CatmullClarkT<OpenMeshPoly, double> catmullClark;
  catmullClark.attach(om);
  EXPECT_TRUE(catmullClark(1));
  catmullClark.detach();
  std::set<Face> faces;
  for (const auto f : om.faces()) {
    Face face;
    for (const auto v : om.fv_ccw_range(f)) {
      const OpenMesh::Vec3d& q = om.point(v);
      face.push_back(key(q[0], q[1], q[2]));
    }
    faces.insert(canonical(face));
  }
  return faces;
}

// Points moved off their symmetric places, so that no two rules can agree by
// the mesh's symmetry alone.
ControlMesh perturbed(const ControlMesh& mesh) {
  MatrixX3 points = mesh.points();
  for (int v = 0; v < points.rows(); ++v)
    for (int a = 0; a < 3; ++a) points(v, a) += 0.05 * std::sin(1.7 * v + 2.3 * a + 0.4);
  return ControlMesh::fromPolygons(points, mesh.topology().faces(), "perturbed");
}

void expectSameRefinement(const ControlMesh& mesh, const std::string& name) {
  ASSERT_TRUE(mesh.isClosed()) << name;
  const std::set<Face> ours = ourRefinement(mesh);
  const std::set<Face> theirs = openMeshRefinement(mesh);
  EXPECT_EQ(ours.size(), static_cast<std::size_t>(subdivide(mesh).mesh.faceCount())) << name << ": faces merged";
  EXPECT_EQ(ours, theirs) << name;
}

// A prism over a regular n-gon: two n-gons and n quads.
ControlMesh prism(int n) {
  MatrixX3 points(2 * n, 3);
  for (int i = 0; i < n; ++i) {
    const double angle = 2 * M_PI * i / n;
    points.row(i) << std::cos(angle), std::sin(angle), 0;
    points.row(n + i) << std::cos(angle), std::sin(angle), 1.5;
  }
  std::vector<Polygon> faces;
  Polygon bottom, top;
  for (int i = n - 1; i >= 0; --i) bottom.push_back(i);
  for (int i = 0; i < n; ++i) top.push_back(n + i);
  faces.push_back(bottom);
  faces.push_back(top);
  for (int i = 0; i < n; ++i) faces.push_back({i, (i + 1) % n, n + (i + 1) % n, n + i});
  return ControlMesh::fromPolygons(points, faces, "prism");
}

TEST(OpenMeshOracle, QuadMeshesOfGenusZeroOneAndTwo) {
  expectSameRefinement(perturbed(makeCube98()), "cube98");
  expectSameRefinement(perturbed(makeTorus32()), "torus32");
  expectSameRefinement(readControlMesh(DYNSUB_DATA_DIR "/Meshes/eight_genus2.obj"), "eight_genus2.obj");
  expectSameRefinement(readControlMesh(DYNSUB_DATA_DIR "/Meshes/kitten_genus1.obj"), "kitten_genus1.obj");
}

TEST(OpenMeshOracle, TrianglesAndPentagons) {
  const MatrixX3 tetrahedron = (MatrixX3(4, 3) << 1, 1, 1, 1, -1, -1, -1, 1, -1, -1, -1, 1).finished();
  expectSameRefinement(ControlMesh::fromPolygons(tetrahedron, {{0, 1, 2}, {0, 3, 1}, {0, 2, 3}, {1, 3, 2}}),
                       "tetrahedron");
  expectSameRefinement(perturbed(prism(3)), "triangular prism");
  expectSameRefinement(perturbed(prism(5)), "pentagonal prism");
}

}  // namespace
}  // namespace dynsub
