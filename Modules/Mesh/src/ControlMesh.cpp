#include "dynsub/ControlMesh.h"

#include <set>

#include "dynsub/Error.h"
#include "dynsub/MeshCheck.h"

namespace dynsub {

ControlMesh ControlMesh::fromPolygons(const Matrix3X& points, const std::vector<Polygon>& faces,
                                      const std::string& source) {
  checkPolygonMesh(points, faces, source);
  ControlMesh mesh;
  std::vector<PolyMesh::VertexHandle> handles;
  handles.reserve(points.rows());
  for (Eigen::Index v = 0; v < points.rows(); ++v) {
    handles.push_back(mesh.mesh_.add_vertex(PolyMesh::Point(points(v, 0), points(v, 1), points(v, 2))));
  }
  std::vector<PolyMesh::VertexHandle> faceHandles;
  for (size_t f = 0; f < faces.size(); ++f) {
    faceHandles.clear();
    for (int v : faces[f]) faceHandles.push_back(handles[v]);
    // The checks above rule out every case in which OpenMesh refuses a face;
    // this guards the assumption rather than trusting it.
    if (!mesh.mesh_.add_face(faceHandles).is_valid()) {
      throw Error(source, "face " + std::to_string(f) + " cannot be added to a manifold mesh");
    }
  }
  return mesh;
}

int ControlMesh::vertexCount() const { return static_cast<int>(mesh_.n_vertices()); }
int ControlMesh::faceCount() const { return static_cast<int>(mesh_.n_faces()); }
int ControlMesh::edgeCount() const { return static_cast<int>(mesh_.n_edges()); }

int ControlMesh::eulerCharacteristic() const { return vertexCount() - edgeCount() + faceCount(); }

int ControlMesh::boundaryLoopCount() const {
  std::set<int> visited;
  int loops = 0;
  for (auto halfedge : mesh_.halfedges()) {
    if (!halfedge.is_boundary() || visited.count(halfedge.idx())) continue;
    ++loops;
    auto h = halfedge;
    do {
      visited.insert(h.idx());
      h = h.next();
    } while (h != halfedge);
  }
  return loops;
}

int ControlMesh::genus() const {
  // chi = 2 - 2g - b for a connected orientable surface with b boundary loops.
  return (2 - eulerCharacteristic() - boundaryLoopCount()) / 2;
}

Matrix3X ControlMesh::points() const {
  Matrix3X result(vertexCount(), 3);
  for (auto vertex : mesh_.vertices()) {
    const PolyMesh::Point& p = mesh_.point(vertex);
    result.row(vertex.idx()) << p[0], p[1], p[2];
  }
  return result;
}

void ControlMesh::setPoints(const Matrix3X& points) {
  if (points.rows() != vertexCount()) {
    throw Error("ControlMesh::setPoints: got " + std::to_string(points.rows()) +
                " points for a mesh of " + std::to_string(vertexCount()) + " vertices");
  }
  for (auto vertex : mesh_.vertices()) {
    const int v = vertex.idx();
    mesh_.set_point(vertex, PolyMesh::Point(points(v, 0), points(v, 1), points(v, 2)));
  }
}

std::vector<Polygon> ControlMesh::faces() const {
  std::vector<Polygon> result;
  result.reserve(mesh_.n_faces());
  for (auto face : mesh_.faces()) {
    Polygon polygon;
    // Start at the face's first halfedge: OpenMesh keeps the order given to add_face.
    for (auto vertex : mesh_.fv_range(face)) polygon.push_back(vertex.idx());
    result.push_back(std::move(polygon));
  }
  return result;
}

}  // namespace dynsub
