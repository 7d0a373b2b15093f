#pragma once
// Face-vertex topology with edge and vertex adjacency: what Catmull-Clark
// refinement and patch gathering need, for whole meshes and for the small local
// meshes around extraordinary vertices. Built from polygons in O(#corners).
//
// Vertices, edges and faces are numbered from 0. Edge e joins edgeVertices(e)
// and has one face (a boundary edge) or two. An edge with more faces throws.
//
// Creases (DeRose, Kass and Truong 1998, with OpenSubdiv's conventions): each
// edge has a sharpness, 0 (smooth) unless set. Each refinement lowers a
// semi-sharp edge's sharpness by 1 (OpenSubdiv's uniform rule); from
// kInfiniteSharpness up an edge stays sharp at every level. Boundary edges are
// always sharp, whatever they are given.
#include <array>
#include <string>
#include <unordered_map>
#include <vector>

namespace dynsub {

using Polygon = std::vector<int>;

constexpr double kInfiniteSharpness = 10.0;
// The exact limit surface refines semi-sharp creases away globally, ceil(s)
// steps that each multiply the elements by four: up to this sharpness.
constexpr double kLargestSemiSharpness = 4.0;

class Topology {
 public:
  Topology() = default;
  Topology(int vertexCount, std::vector<Polygon> faces);

  int vertexCount() const { return vertexCount_; }
  int faceCount() const { return static_cast<int>(faces_.size()); }
  int edgeCount() const { return static_cast<int>(edgeVertices_.size()); }

  const std::vector<Polygon>& faces() const { return faces_; }
  const Polygon& face(int f) const { return faces_[f]; }
  int faceSize(int f) const { return static_cast<int>(faces_[f].size()); }
  // The edge from corner k to corner k+1 of face f.
  int faceEdge(int f, int k) const { return faceEdges_[f][k]; }
  // Index of vertex v among the corners of face f, or -1.
  int corner(int f, int v) const;

  // The edge joining a and b, or -1.
  int findEdge(int a, int b) const;
  const std::array<int, 2>& edgeVertices(int e) const { return edgeVertices_[e]; }
  // The faces of edge e; the second is -1 for a boundary edge.
  const std::array<int, 2>& edgeFaces(int e) const { return edgeFaces_[e]; }
  bool isBoundaryEdge(int e) const { return edgeFaces_[e][1] < 0; }
  // The face of edge e other than f, or -1 on a boundary.
  int otherFace(int e, int f) const;

  const std::vector<int>& vertexFaces(int v) const { return vertexFaces_[v]; }
  const std::vector<int>& vertexEdges(int v) const { return vertexEdges_[v]; }
  bool isBoundaryVertex(int v) const;
  double edgeSharpness(int e) const { return edgeSharpness_.empty() ? 0.0 : edgeSharpness_[e]; }
  bool hasCreases() const { return !edgeSharpness_.empty(); }
  // One value per edge, finite and >= 0 (throws dynsub::Error naming `source`
  // and the edge otherwise); all zeros leave the topology without creases.
  void setEdgeSharpness(std::vector<double> sharpness, const std::string& source = "topology");
  // Boundary edges and edges of sharpness >= kInfiniteSharpness.
  bool isSharpEdge(int e) const { return isBoundaryEdge(e) || edgeSharpness(e) >= kInfiniteSharpness; }
  // The faces at vertex v grouped into the fans its sharp edges separate: one
  // fan for a vertex with fewer than two sharp edges, one per pair of
  // neighbouring sharp edges otherwise.
  std::vector<std::vector<int>> sharpSectors(int v) const;

  // Regular for Catmull-Clark: an interior vertex with 4 edges, a boundary
  // vertex with 2 faces, or a corner (a boundary vertex with 1 face). Around a
  // regular vertex the limit surface is a bicubic B-spline.
  bool isRegularVertex(int v) const;

 private:
  int vertexCount_ = 0;
  std::vector<Polygon> faces_;
  std::vector<std::vector<int>> faceEdges_;
  std::vector<std::array<int, 2>> edgeVertices_;
  std::vector<std::array<int, 2>> edgeFaces_;
  std::vector<std::vector<int>> vertexFaces_;
  std::vector<std::vector<int>> vertexEdges_;
  std::unordered_map<unsigned long long, int> edgeIndex_;
  std::vector<double> edgeSharpness_;  // empty: every edge smooth
};

}  // namespace dynsub
