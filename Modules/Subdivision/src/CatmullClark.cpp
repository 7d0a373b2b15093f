#include "dynsub/CatmullClark.h"

#include <algorithm>

#include "dynsub/Error.h"

namespace dynsub {

namespace {

enum class VertexRule { Smooth, Crease, Corner };

// No sharp edge, or one (a dart): smooth; two: a crease; more: a corner.
VertexRule ruleOf(size_t sharpEdges) {
  if (sharpEdges <= 1) return VertexRule::Smooth;
  return sharpEdges == 2 ? VertexRule::Crease : VertexRule::Corner;
}

}  // namespace

double childSharpness(double sharpness) {
  if (sharpness >= kInfiniteSharpness) return sharpness;
  return sharpness > 1.0 ? sharpness - 1.0 : 0.0;
}

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

  // Adds `weight` times vertex v's point under `rule` to row v; `sharp` holds
  // its sharp edges (the crease rule uses their other ends).
  auto addVertexRule = [&](int v, VertexRule rule, const std::vector<int>& sharp, double weight) {
    auto otherEnd = [&](int e) {
      const auto [a, b] = topology.edgeVertices(e);
      return a == v ? b : a;
    };
    if (rule == VertexRule::Corner) {
      weights.emplace_back(v, v, weight);
    } else if (rule == VertexRule::Crease) {
      weights.emplace_back(v, v, 0.75 * weight);
      weights.emplace_back(v, otherEnd(sharp[0]), 0.125 * weight);
      weights.emplace_back(v, otherEnd(sharp[1]), 0.125 * weight);
    } else {
      // (F + 2R + (n-3)V) / n, with F and R averages over n faces and n edges.
      const std::vector<int>& edges = topology.vertexEdges(v);
      const double n = static_cast<double>(edges.size());
      weights.emplace_back(v, v, weight * (n - 3.0) / n);
      for (int f : topology.vertexFaces(v)) addFacePoint(v, f, weight / (n * n));
      for (int e : edges) {
        const auto [a, b] = topology.edgeVertices(e);
        weights.emplace_back(v, a, weight / (n * n));
        weights.emplace_back(v, b, weight / (n * n));
      }
    }
  };

  for (int e = 0; e < edgeCount; ++e) {
    const auto [a, b] = topology.edgeVertices(e);
    const int row = edgePointBase + e;
    // Sharpness s in (0, 1) blends the midpoint (weight s) with the smooth rule.
    const double sharp = topology.isBoundaryEdge(e) ? 1.0 : std::min(1.0, topology.edgeSharpness(e));
    weights.emplace_back(row, a, 0.25 + 0.25 * sharp);
    weights.emplace_back(row, b, 0.25 + 0.25 * sharp);
    if (sharp < 1.0) {
      addFacePoint(row, topology.edgeFaces(e)[0], 0.25 * (1.0 - sharp));
      addFacePoint(row, topology.edgeFaces(e)[1], 0.25 * (1.0 - sharp));
    }
  }

  std::vector<int> sharpNow, sharpAfter;  // a vertex's sharp edges before and after the step
  for (int v = 0; v < vertexCount; ++v) {
    const std::vector<int>& edges = topology.vertexEdges(v);
    const std::vector<int>& faces = topology.vertexFaces(v);
    if (faces.empty()) {
      weights.emplace_back(v, v, 1.0);
      continue;
    }
    // The vertex's rule, before and after this step, from its sharp edges.
    // A corner (one face) and (only in the truncated local meshes around
    // extraordinary vertices, where such points are never used) a boundary
    // vertex without two boundary edges stay where they are.
    int boundaryEdges = 0;
    sharpNow.clear();
    sharpAfter.clear();
    double transitionSum = 0.0;
    int transitions = 0;
    for (int e : edges) {
      if (topology.isBoundaryEdge(e)) {
        ++boundaryEdges;
        sharpNow.push_back(e);
        sharpAfter.push_back(e);
        continue;
      }
      const double now = topology.edgeSharpness(e), after = childSharpness(now);
      if (now > 0.0) sharpNow.push_back(e);
      if (after > 0.0) sharpAfter.push_back(e);
      if (now > 0.0 && after <= 0.0) transitionSum += now, ++transitions;
    }
    const bool corner = boundaryEdges > 0 && (faces.size() == 1 || boundaryEdges != 2);
    const VertexRule now = corner ? VertexRule::Corner : ruleOf(sharpNow.size());
    const VertexRule after = corner ? VertexRule::Corner : ruleOf(sharpAfter.size());
    // OpenSubdiv's transition: when a sharpness decays to 0 in this step, the
    // two rules are blended by the decaying sharpnesses' mean.
    const double weightNow = now == after ? 1.0 : std::min(1.0, transitionSum / transitions);
    addVertexRule(v, now, sharpNow, weightNow);
    if (weightNow < 1.0) addVertexRule(v, after, sharpAfter, 1.0 - weightNow);
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
  if (topology.hasCreases()) {
    // Each half of an edge has the edge's lowered sharpness; new edges are smooth.
    std::vector<double> sharpness(result.topology.edgeCount(), 0.0);
    for (int e = 0; e < edgeCount; ++e) {
      const double after = childSharpness(topology.edgeSharpness(e));
      for (int end : topology.edgeVertices(e)) sharpness[result.topology.findEdge(end, edgePointBase + e)] = after;
    }
    result.topology.setEdgeSharpness(std::move(sharpness));
  }
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
