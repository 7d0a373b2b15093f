#include "dynsub/Topology.h"

#include <algorithm>

#include "dynsub/Error.h"

namespace dynsub {

namespace {
unsigned long long edgeKey(int a, int b) {
  return (static_cast<unsigned long long>(std::min(a, b)) << 32) | static_cast<unsigned>(std::max(a, b));
}
}  // namespace

Topology::Topology(int vertexCount, std::vector<Polygon> faces)
    : vertexCount_(vertexCount), faces_(std::move(faces)) {
  vertexFaces_.resize(vertexCount_);
  vertexEdges_.resize(vertexCount_);
  faceEdges_.resize(faces_.size());
  for (int f = 0; f < faceCount(); ++f) {
    const Polygon& polygon = faces_[f];
    const int n = static_cast<int>(polygon.size());
    faceEdges_[f].resize(n);
    for (int k = 0; k < n; ++k) {
      const int a = polygon[k];
      const int b = polygon[(k + 1) % n];
      vertexFaces_[a].push_back(f);
      auto [it, inserted] = edgeIndex_.emplace(edgeKey(a, b), edgeCount());
      if (inserted) {
        edgeVertices_.push_back({a, b});
        edgeFaces_.push_back({f, -1});
        vertexEdges_[a].push_back(it->second);
        vertexEdges_[b].push_back(it->second);
      } else if (edgeFaces_[it->second][1] < 0) {
        edgeFaces_[it->second][1] = f;
      } else {
        throw Error("topology: edge (" + std::to_string(a) + ", " + std::to_string(b) +
                    ") has more than two faces");
      }
      faceEdges_[f][k] = it->second;
    }
  }
}

int Topology::corner(int f, int v) const {
  const Polygon& polygon = faces_[f];
  for (size_t k = 0; k < polygon.size(); ++k) {
    if (polygon[k] == v) return static_cast<int>(k);
  }
  return -1;
}

int Topology::findEdge(int a, int b) const {
  auto it = edgeIndex_.find(edgeKey(a, b));
  return it == edgeIndex_.end() ? -1 : it->second;
}

int Topology::otherFace(int e, int f) const {
  const std::array<int, 2>& pair = edgeFaces_[e];
  return pair[0] == f ? pair[1] : pair[0];
}

bool Topology::isBoundaryVertex(int v) const {
  for (int e : vertexEdges_[v]) {
    if (isBoundaryEdge(e)) return true;
  }
  return false;
}

bool Topology::isRegularVertex(int v) const {
  const size_t faces = vertexFaces_[v].size();
  if (!isBoundaryVertex(v)) return vertexEdges_[v].size() == 4;
  return faces == 1 || (faces == 2 && vertexEdges_[v].size() == 3);
}

}  // namespace dynsub
