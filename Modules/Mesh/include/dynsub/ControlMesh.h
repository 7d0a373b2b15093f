#pragma once
// The control mesh of a Catmull-Clark surface: a polygon mesh of any genus
// (triangles, quads, n-gons), closed or with boundaries, with double-precision
// points in mm and its Topology (faces, edges and their adjacency).
//
// Preconditions enforced by fromPolygons() (see MeshCheck.h): at least one face;
// every vertex used; every face has >= 3 distinct vertices and non-zero area;
// every edge has one or two faces; every vertex has one fan of faces; faces are
// consistently oriented (the outward normal follows the right-hand rule).
#include <memory>
#include <string>
#include <vector>

#include "dynsub/Topology.h"
#include "dynsub/Types.h"

namespace dynsub {

// A crease tag: the edge joining vertices a and b, with its sharpness
// (Topology.h: 0 smooth, up to kInfiniteSharpness semi-sharp, from it on sharp).
struct Crease {
  int a = 0;
  int b = 0;
  double sharpness = 0;
};

class ControlMesh {
 public:
  ControlMesh();

  // Checks the polygons (throws dynsub::Error naming `source` and the problem,
  // with vertices and faces counted from `firstNumber` as checkPolygonMesh
  // does) and builds the mesh. Vertex i of the mesh is row i of `points`;
  // face f is faces[f] with the same vertex order.
  static ControlMesh fromPolygons(const MatrixX3& points, const std::vector<Polygon>& faces,
                                  const std::string& source = "mesh", int firstNumber = 0);
  // A mesh whose topology is already known to be valid: a refinement of a
  // checked mesh (CatmullClark.h) is manifold and consistently oriented by
  // construction, so only the points are checked (finite, one per vertex).
  static ControlMesh fromTopology(const MatrixX3& points, Topology topology, const std::string& source = "mesh");

  int vertexCount() const { return topology_->vertexCount(); }
  int faceCount() const { return topology_->faceCount(); }
  int edgeCount() const { return topology_->edgeCount(); }
  // #vertices - #edges + #faces.
  int eulerCharacteristic() const;
  int boundaryLoopCount() const;
  bool isClosed() const { return boundaryLoopCount() == 0; }
  // The connected pieces of the surface (two cubes are 2).
  int pieceCount() const;
  // The genus of the surface from its Euler characteristic: the sum of its
  // pieces' genera.
  int genus() const;

  const MatrixX3& points() const { return points_; }
  // Replaces the vertex positions; `points` must have vertexCount() rows.
  void setPoints(const MatrixX3& points);
  const std::vector<Polygon>& faces() const { return topology_->faces(); }
  const Topology& topology() const { return *topology_; }

  // Tags edges as creases (the others keep their sharpness). Throws
  // dynsub::Error naming `source` if a tag names no edge of the mesh or its
  // sharpness is negative, NaN or infinite.
  void setCreases(const std::vector<Crease>& creases, const std::string& source = "mesh");
  // The edges of non-zero sharpness, in edge order.
  std::vector<Crease> creases() const;

 private:
  MatrixX3 points_;
  // Shared: copies of a mesh (one per level, per result) differ only in their points.
  std::shared_ptr<const Topology> topology_;
};

// The volume a closed mesh's polygons enclose (mm^3), signed: positive when
// they face outward by the right-hand rule, negative when they face inward.
double enclosedVolume(const ControlMesh& mesh);

// Throws dynsub::Error naming `source` when closed `mesh` faces inward: its
// forces (a pressure, an inflation) would push the wrong way, and its results
// would be inside out in every viewer.
void requireOutwardFacing(const ControlMesh& mesh, const std::string& source);

}  // namespace dynsub
