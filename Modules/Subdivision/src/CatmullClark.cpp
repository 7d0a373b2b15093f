#include "dynsub/CatmullClark.h"

#include "dynsub/Error.h"

namespace dynsub {

Refinement refine(const Topology& topology) {
  const int vertexCount = topology.vertexCount();
  const int edgeCount = topology.edgeCount();
  const int faceCount = topology.faceCount();
  const int edgePointBase = vertexCount;
  const int facePointBase = vertexCount + edgeCount;

  std::vector<Triplet> weights;
  weights.reserve(16 * (vertexCount + edgeCount + faceCount));
  // Adds `weight` times the face point of f to row `row`.
  auto addFacePoint = [&](int row, int f, double weight) {
    const Polygon& face = topology.face(f);
    for (int v : face) weights.emplace_back(row, v, weight / face.size());
  };

  for (int f = 0; f < faceCount; ++f) addFacePoint(facePointBase + f, f, 1.0);

  for (int e = 0; e < edgeCount; ++e) {
    const auto [a, b] = topology.edgeVertices(e);
    const int row = edgePointBase + e;
    if (topology.isBoundaryEdge(e)) {
      weights.emplace_back(row, a, 0.5);
      weights.emplace_back(row, b, 0.5);
    } else {
      weights.emplace_back(row, a, 0.25);
      weights.emplace_back(row, b, 0.25);
      addFacePoint(row, topology.edgeFaces(e)[0], 0.25);
      addFacePoint(row, topology.edgeFaces(e)[1], 0.25);
    }
  }

  for (int v = 0; v < vertexCount; ++v) {
    const std::vector<int>& edges = topology.vertexEdges(v);
    const std::vector<int>& faces = topology.vertexFaces(v);
    if (faces.empty()) {
      weights.emplace_back(v, v, 1.0);
      continue;
    }
    if (topology.isBoundaryVertex(v)) {
      std::vector<int> boundaryNeighbours;
      for (int e : edges) {
        if (!topology.isBoundaryEdge(e)) continue;
        const auto [a, b] = topology.edgeVertices(e);
        boundaryNeighbours.push_back(a == v ? b : a);
      }
      // A corner, and (only in the truncated local meshes around extraordinary
      // vertices, where such points are never used) a vertex with more than two
      // boundary edges, stay where they are.
      if (faces.size() == 1 || boundaryNeighbours.size() != 2) {
        weights.emplace_back(v, v, 1.0);
      } else {
        weights.emplace_back(v, v, 0.75);
        weights.emplace_back(v, boundaryNeighbours[0], 0.125);
        weights.emplace_back(v, boundaryNeighbours[1], 0.125);
      }
      continue;
    }
    const double n = static_cast<double>(edges.size());
    // (F + 2R + (n-3)V) / n, with F and R averages over n faces and n edges.
    weights.emplace_back(v, v, (n - 3.0) / n);
    for (int f : faces) addFacePoint(v, f, 1.0 / (n * n));
    for (int e : edges) {
      const auto [a, b] = topology.edgeVertices(e);
      weights.emplace_back(v, a, 1.0 / (n * n));
      weights.emplace_back(v, b, 1.0 / (n * n));
    }
  }

  Refinement result;
  result.subdivisionMatrix.resize(facePointBase + faceCount, vertexCount);
  result.subdivisionMatrix.setFromTriplets(weights.begin(), weights.end());

  std::vector<Polygon> children;
  result.childFaceOffset.resize(faceCount);
  for (int f = 0; f < faceCount; ++f) {
    result.childFaceOffset[f] = static_cast<int>(children.size());
    const int n = topology.faceSize(f);
    for (int k = 0; k < n; ++k) {
      children.push_back({topology.face(f)[k], edgePointBase + topology.faceEdge(f, k), facePointBase + f,
                          edgePointBase + topology.faceEdge(f, (k + n - 1) % n)});
    }
  }
  result.topology = Topology(facePointBase + faceCount, std::move(children));
  return result;
}

SubdividedMesh subdivide(const ControlMesh& mesh) {
  Refinement refinement = refine(mesh.topology());
  const MatrixX3 points = refinement.subdivisionMatrix * mesh.points();
  SubdividedMesh result{ControlMesh::fromTopology(points, std::move(refinement.topology), "refined mesh"), {}};
  result.subdivisionMatrix.swap(refinement.subdivisionMatrix);  // Eigen 3.4's sparse matrices have no move
  return result;
}

}  // namespace dynsub
