#include "dynsub/ControlMesh.h"

#include <numeric>
#include <sstream>

#include "dynsub/Error.h"
#include "dynsub/MeshCheck.h"

namespace dynsub {

ControlMesh::ControlMesh() : topology_(std::make_shared<const Topology>()) {}

ControlMesh ControlMesh::fromPolygons(const MatrixX3& points, const std::vector<Polygon>& faces,
                                      const std::string& source, int firstNumber) {
  checkPolygonMesh(points, faces, source, firstNumber);
  ControlMesh mesh;
  mesh.points_ = points;
  mesh.topology_ = std::make_shared<const Topology>(static_cast<int>(points.rows()), faces);
  return mesh;
}

ControlMesh ControlMesh::fromTopology(const MatrixX3& points, Topology topology, const std::string& source) {
  if (points.rows() != topology.vertexCount())
    throw Error(source, std::to_string(points.rows()) + " points for " + std::to_string(topology.vertexCount()) +
                            " vertices");
  for (Eigen::Index v = 0; v < points.rows(); ++v)
    if (!points.row(v).allFinite())
      throw Error(source, "vertex " + std::to_string(v) + " has a coordinate that is NaN or infinite");
  ControlMesh mesh;
  mesh.points_ = points;
  mesh.topology_ = std::make_shared<const Topology>(std::move(topology));
  return mesh;
}

void ControlMesh::setCreases(const std::vector<Crease>& creases, const std::string& source) {
  if (creases.empty()) return;
  Topology topology = *topology_;
  std::vector<double> sharpness(topology.edgeCount());
  for (int e = 0; e < topology.edgeCount(); ++e) sharpness[e] = topology.edgeSharpness(e);
  // An edge tagged twice with two sharpnesses is a contradiction, not an
  // override: which tag a reader keeps differs from tool to tool.
  std::vector<char> tagged(topology.edgeCount(), 0);
  for (const Crease& crease : creases) {
    const std::string edge = "crease (" + std::to_string(crease.a) + ", " + std::to_string(crease.b) + ")";
    const bool inRange = crease.a >= 0 && crease.b >= 0 && crease.a < vertexCount() && crease.b < vertexCount();
    const int e = inRange ? topology.findEdge(crease.a, crease.b) : -1;
    if (e < 0) throw Error(source, edge + " is not an edge of the mesh (vertices are numbered from 0)");
    if (tagged[e] && sharpness[e] != crease.sharpness) {
      std::ostringstream both;
      both << sharpness[e] << " and " << crease.sharpness;
      throw Error(source, edge + " is tagged twice, with sharpness " + both.str() + ": tag each edge once");
    }
    tagged[e] = 1;
    sharpness[e] = crease.sharpness;
  }
  topology.setEdgeSharpness(std::move(sharpness), source);
  checkCreases(topology, source);
  topology_ = std::make_shared<const Topology>(std::move(topology));
}

std::vector<Crease> ControlMesh::creases() const {
  std::vector<Crease> result;
  for (int e = 0; e < edgeCount(); ++e) {
    const double sharpness = topology_->edgeSharpness(e);
    if (sharpness > 0.0) result.push_back({topology_->edgeVertices(e)[0], topology_->edgeVertices(e)[1], sharpness});
  }
  return result;
}

int ControlMesh::eulerCharacteristic() const { return vertexCount() - edgeCount() + faceCount(); }

namespace {

// Each vertex's set, by its representative, once the edges `joins` accepts
// have joined their two ends.
template <typename Joins>
std::vector<int> joinedVertices(const Topology& t, Joins joins) {
  std::vector<int> parent(t.vertexCount());
  std::iota(parent.begin(), parent.end(), 0);
  auto find = [&parent](int v) {
    while (parent[v] != v) v = parent[v] = parent[parent[v]];
    return v;
  };
  for (int e = 0; e < t.edgeCount(); ++e) {
    if (!joins(e)) continue;
    const auto [a, b] = t.edgeVertices(e);
    parent[find(a)] = find(b);
  }
  for (int v = 0; v < t.vertexCount(); ++v) parent[v] = find(v);
  return parent;
}

}  // namespace

int ControlMesh::boundaryLoopCount() const {
  // Every boundary vertex of a manifold mesh has exactly two boundary edges, so
  // the loops are the connected sets of boundary edges.
  const Topology& t = *topology_;
  std::vector<bool> onBoundary(t.vertexCount(), false);
  for (int e = 0; e < t.edgeCount(); ++e) {
    if (!t.isBoundaryEdge(e)) continue;
    const auto [a, b] = t.edgeVertices(e);
    onBoundary[a] = onBoundary[b] = true;
  }
  const std::vector<int> set = joinedVertices(t, [&t](int e) { return t.isBoundaryEdge(e); });
  int loops = 0;
  for (int v = 0; v < t.vertexCount(); ++v) loops += onBoundary[v] && set[v] == v;
  return loops;
}

int ControlMesh::pieceCount() const {
  // Every vertex lies on a face (MeshCheck.h), so the pieces are the
  // connected sets of edges.
  const std::vector<int> set = joinedVertices(*topology_, [](int) { return true; });
  int pieces = 0;
  for (int v = 0; v < vertexCount(); ++v) pieces += set[v] == v;
  return pieces;
}

int ControlMesh::genus() const {
  // chi = 2 - 2g - b for each connected orientable piece with b boundary
  // loops; summed over the pieces, chi = 2 pieces - 2 g - b.
  return (2 * pieceCount() - eulerCharacteristic() - boundaryLoopCount()) / 2;
}

double enclosedVolume(const ControlMesh& mesh) {
  const MatrixX3& p = mesh.points();
  double sixTimes = 0;
  for (const Polygon& face : mesh.faces())
    for (std::size_t k = 1; k + 1 < face.size(); ++k)
      sixTimes += p.row(face[0]).dot(p.row(face[k]).cross(p.row(face[k + 1])));
  return sixTimes / 6.0;
}

void requireOutwardFacing(const ControlMesh& mesh, const std::string& source) {
  const double volume = enclosedVolume(mesh);
  if (volume >= 0) return;
  std::ostringstream message;
  message << "the control mesh faces inward (the volume it encloses is " << volume
          << " mm^3 as its faces are ordered): reverse the order of every face's vertices (MeshLab: Invert Faces "
             "Orientation; Blender: Flip Normals)";
  throw Error(source, message.str());
}

void ControlMesh::setPoints(const MatrixX3& points) {
  if (points.rows() != vertexCount()) {
    throw Error("ControlMesh::setPoints: got " + std::to_string(points.rows()) +
                " points for a mesh of " + std::to_string(vertexCount()) + " vertices");
  }
  points_ = points;
}

}  // namespace dynsub
