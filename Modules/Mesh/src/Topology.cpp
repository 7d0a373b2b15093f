#include "dynsub/Topology.h"

#include <algorithm>
#include <cmath>

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

void Topology::setEdgeSharpness(std::vector<double> sharpness, const std::string& source) {
  if (static_cast<int>(sharpness.size()) != edgeCount()) {
    throw Error(source, std::to_string(sharpness.size()) + " sharpness values for " + std::to_string(edgeCount()) +
                            " edges");
  }
  bool creased = false;
  for (int e = 0; e < edgeCount(); ++e) {
    if (!(sharpness[e] >= 0.0 && std::isfinite(sharpness[e]))) {
      throw Error(source, "crease (" + std::to_string(edgeVertices_[e][0]) + ", " +
                              std::to_string(edgeVertices_[e][1]) + ") has sharpness " +
                              std::to_string(sharpness[e]) + " (expected a finite value >= 0)");
    }
    creased = creased || sharpness[e] > 0.0;
  }
  if (creased) {
    edgeSharpness_ = std::move(sharpness);
  } else {
    edgeSharpness_.clear();
  }
}

std::vector<std::vector<int>> Topology::sharpSectors(int v) const {
  // Faces at v that share a smooth edge at v are in one sector.
  const std::vector<int>& faces = vertexFaces_[v];
  std::vector<int> sector(faces.size());
  for (size_t i = 0; i < faces.size(); ++i) sector[i] = static_cast<int>(i);
  auto find = [&sector](int i) {
    while (sector[i] != i) i = sector[i] = sector[sector[i]];
    return i;
  };
  auto indexOf = [&faces](int f) { return static_cast<int>(std::find(faces.begin(), faces.end(), f) - faces.begin()); };
  for (int e : vertexEdges_[v]) {
    if (isSharpEdge(e)) continue;
    sector[find(indexOf(edgeFaces_[e][0]))] = find(indexOf(edgeFaces_[e][1]));
  }
  std::vector<std::vector<int>> result;
  std::vector<int> slot(faces.size(), -1);
  for (size_t i = 0; i < faces.size(); ++i) {
    const int root = find(static_cast<int>(i));
    if (slot[root] < 0) {
      slot[root] = static_cast<int>(result.size());
      result.emplace_back();
    }
    result[slot[root]].push_back(faces[i]);
  }
  return result;
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
