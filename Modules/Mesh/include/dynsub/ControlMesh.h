#pragma once
// The control mesh of a Catmull-Clark surface: a polygon mesh of any genus
// (triangles, quads, n-gons), closed or with boundaries, stored in OpenMesh with
// double-precision points in mm.
//
// Preconditions enforced by fromPolygons() (see MeshCheck.h): at least one face;
// every vertex used; every face has >= 3 distinct vertices and non-zero area;
// every edge has one or two faces; every vertex has one fan of faces; faces are
// consistently oriented (the outward normal follows the right-hand rule).
#include <string>
#include <vector>

#include <OpenMesh/Core/Mesh/PolyMesh_ArrayKernelT.hh>

#include "dynsub/Types.h"

namespace dynsub {

struct DoublePrecisionTraits : public OpenMesh::DefaultTraits {
  using Point = OpenMesh::Vec3d;
  using Normal = OpenMesh::Vec3d;
};
using PolyMesh = OpenMesh::PolyMesh_ArrayKernelT<DoublePrecisionTraits>;

// A polygon face as the indices of its vertices, in order around the face.
using Polygon = std::vector<int>;

class ControlMesh {
 public:
  ControlMesh() = default;

  // Checks the polygons (throws dynsub::Error naming `source` and the problem)
  // and builds the mesh. Vertex i of the mesh is row i of `points`; face f is
  // faces[f] with the same vertex order.
  static ControlMesh fromPolygons(const Matrix3X& points, const std::vector<Polygon>& faces,
                                  const std::string& source = "mesh");

  int vertexCount() const;
  int faceCount() const;
  int edgeCount() const;
  // #vertices - #edges + #faces.
  int eulerCharacteristic() const;
  int boundaryLoopCount() const;
  bool isClosed() const { return boundaryLoopCount() == 0; }
  // Genus of the surface, from the Euler characteristic, assuming it is connected.
  int genus() const;

  Matrix3X points() const;
  // Replaces the vertex positions; `points` must have vertexCount() rows.
  void setPoints(const Matrix3X& points);
  std::vector<Polygon> faces() const;

  // Direct halfedge access for code that navigates the mesh.
  const PolyMesh& polyMesh() const { return mesh_; }

 private:
  PolyMesh mesh_;
};

}  // namespace dynsub
