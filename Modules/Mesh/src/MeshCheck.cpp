#include "dynsub/MeshCheck.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <numeric>
#include <string>
#include <tuple>

#include "dynsub/Coordinates.h"
#include "dynsub/Error.h"
#include "dynsub/PolygonArea.h"
#include "dynsub/Topology.h"

namespace dynsub {

namespace {

// Number of fans the faces around one vertex form: faces are in one fan when
// they are linked through edges incident to the vertex.
int fanCount(int vertex, const std::vector<int>& incidentFaces,
             const std::vector<std::vector<int>>& faces) {
  std::vector<int> parent(incidentFaces.size());
  std::iota(parent.begin(), parent.end(), 0);
  auto find = [&parent](int i) {
    while (parent[i] != i) i = parent[i] = parent[parent[i]];
    return i;
  };
  // Neighbour vertex across an edge at `vertex` -> first incident face seen.
  std::map<int, int> firstFaceAtNeighbour;
  for (size_t i = 0; i < incidentFaces.size(); ++i) {
    const std::vector<int>& face = faces[incidentFaces[i]];
    const size_t n = face.size();
    for (size_t k = 0; k < n; ++k) {
      if (face[k] != vertex) continue;
      for (int neighbour : {face[(k + 1) % n], face[(k + n - 1) % n]}) {
        auto [it, inserted] = firstFaceAtNeighbour.emplace(neighbour, static_cast<int>(i));
        if (!inserted) parent[find(static_cast<int>(i))] = find(it->second);
      }
    }
  }
  int count = 0;
  for (size_t i = 0; i < parent.size(); ++i) count += find(static_cast<int>(i)) == static_cast<int>(i);
  return count;
}

}  // namespace

void checkPolygonMesh(const MatrixX3& points, const std::vector<std::vector<int>>& faces, const std::string& source,
                      int firstNumber) {
  // A vertex's or a face's number as the file counts them.
  const auto number = [firstNumber](long long i) { return std::to_string(i + firstNumber); };
  const auto edgeName = [&number](int a, int b) { return "(" + number(a) + ", " + number(b) + ")"; };
  const int vertexCount = static_cast<int>(points.rows());
  if (vertexCount == 0) throw Error(source, "the mesh has no vertices");
  if (faces.empty()) throw Error(source, "the mesh has no faces");
  for (int v = 0; v < vertexCount; ++v) {
    if (!points.row(v).allFinite()) {
      throw Error(source, "vertex " + number(v) + " has a coordinate that is NaN or infinite");
    }
    // Areas of such coordinates overflow, and every face would look degenerate.
    const std::string beyond = beyondLargestCoordinate(points.row(v).transpose());
    if (!beyond.empty()) throw Error(source, "vertex " + number(v) + " " + beyond);
  }
  const double minimumArea = degenerateArea(points);

  std::vector<std::vector<int>> vertexFaces(vertexCount);
  // Every face's edges, each as it runs in that face.
  struct FaceEdge {
    int low, high;  // the edge's vertices, in order
    int from;       // where the face runs along it from
    int face;
    size_t order;  // its place in the faces' order
  };
  std::vector<FaceEdge> faceEdges;
  for (size_t f = 0; f < faces.size(); ++f) {
    const std::vector<int>& face = faces[f];
    const std::string faceName = "face " + number(f);
    if (face.size() < 3) {
      throw Error(source, faceName + " has " + std::to_string(face.size()) +
                              " vertices; a face needs at least 3");
    }
    for (int v : face) {
      if (v < 0 || v >= vertexCount) {
        throw Error(source, faceName + " uses vertex " + number(v) + ", but the mesh has " +
                                std::to_string(vertexCount) + " vertices");
      }
    }
    for (size_t i = 0; i < face.size(); ++i) {
      for (size_t j = i + 1; j < face.size(); ++j) {
        if (face[i] == face[j]) {
          throw Error(source, faceName + " is degenerate: it uses vertex " + number(face[i]) + " twice");
        }
      }
    }
    if (const std::string noArea = noAreaReason(points, face, minimumArea); !noArea.empty()) {
      throw Error(source, faceName + " is degenerate: " + noArea);
    }
    for (size_t k = 0; k < face.size(); ++k) {
      const int a = face[k];
      const int b = face[(k + 1) % face.size()];
      vertexFaces[a].push_back(static_cast<int>(f));
      faceEdges.push_back({std::min(a, b), std::max(a, b), a, static_cast<int>(f), faceEdges.size()});
    }
  }
  // Sorted, the faces of one edge are neighbours, those running along it the
  // same way too, each run in the faces' order.
  std::sort(faceEdges.begin(), faceEdges.end(), [](const FaceEdge& x, const FaceEdge& y) {
    return std::tie(x.low, x.high, x.from, x.order) < std::tie(y.low, y.high, y.from, y.order);
  });
  for (size_t first = 0, last = 0; first < faceEdges.size(); first = last) {
    while (last < faceEdges.size() && faceEdges[last].low == faceEdges[first].low &&
           faceEdges[last].high == faceEdges[first].high)
      ++last;
    if (last - first > 2) {
      throw Error(source, "edge " + edgeName(faceEdges[first].low, faceEdges[first].high) + " is shared by " +
                              std::to_string(last - first) + " faces: the mesh is not manifold");
    }
  }
  // Checked after the edges' face counts: an edge with three faces always
  // repeats a direction, and "not manifold" is then the truer message. Of
  // two faces along an edge the same way, the one met first in the faces'
  // order is named, with the face that ran along it before.
  const FaceEdge* repeated = nullptr;
  const FaceEdge* before = nullptr;
  for (size_t e = 1; e < faceEdges.size(); ++e) {
    const FaceEdge& x = faceEdges[e - 1];
    const FaceEdge& y = faceEdges[e];
    if (x.low == y.low && x.high == y.high && x.from == y.from && (!repeated || y.order < repeated->order)) {
      repeated = &y;
      before = &x;
    }
  }
  if (repeated) {
    const int to = repeated->from == repeated->low ? repeated->high : repeated->low;
    throw Error(source, "faces " + number(before->face) + " and " + number(repeated->face) + " both run along edge " +
                            edgeName(repeated->from, to) +
                            " in the same direction: the orientation is inconsistent (or a face is repeated)");
  }
  for (int v = 0; v < vertexCount; ++v) {
    if (vertexFaces[v].empty()) {
      throw Error(source, "vertex " + number(v) + " is isolated: no face uses it");
    }
    const int fans = fanCount(v, vertexFaces[v], faces);
    if (fans > 1) {
      throw Error(source, "vertex " + number(v) + " joins " + std::to_string(fans) +
                              " separate fans of faces: the mesh is not manifold there");
    }
    const size_t faceCount = vertexFaces[v].size();
    if (faceCount > static_cast<size_t>(kLargestValence)) {
      throw Error(source, "vertex " + number(v) + " has " + std::to_string(faceCount) + " faces around it; at most " +
                              std::to_string(kLargestValence) +
                              " are supported (the surface's cost near a vertex grows faster than the cube of "
                              "their number). Remesh it with fewer faces around that vertex");
    }
  }
}

// Vertices are named as crease tags name them, from 0 (an OBJ's other
// messages count its vertices from 1, as its faces do), the smaller first.
void checkCreases(const Topology& topology, const std::string& source) {
  if (!topology.hasCreases()) return;
  for (int e = 0; e < topology.edgeCount(); ++e) {
    const double sharpness = topology.edgeSharpness(e);
    if (sharpness > kLargestSemiSharpness && sharpness < kInfiniteSharpness) {
      const auto [a, b] = topology.edgeVertices(e);
      throw Error(source, "crease (" + std::to_string(std::min(a, b)) + ", " + std::to_string(std::max(a, b)) +
                              ") has sharpness " + std::to_string(sharpness) + ": semi-sharp creases up to " +
                              std::to_string(static_cast<int>(kLargestSemiSharpness)) +
                              " are supported (each step of sharpness refines the whole surface once), and from " +
                              std::to_string(static_cast<int>(kInfiniteSharpness)) + " on a crease is sharp");
    }
  }
  for (int v = 0; v < topology.vertexCount(); ++v) {
    int sharp = 0, infinite = 0;
    for (int e : topology.vertexEdges(v)) {
      sharp += topology.isSharpEdge(e);
      infinite += !topology.isBoundaryEdge(e) && topology.edgeSharpness(e) >= kInfiniteSharpness;
    }
    if (infinite == 0) continue;
    const std::string at = "vertex " + std::to_string(v) + " (counted from 0, as crease tags count): ";
    if (sharp == 1) {
      const std::string below = std::to_string(static_cast<int>(kInfiniteSharpness));
      throw Error(source, at +
                              "a sharp crease ends inside the surface (a dart), which is not supported; end it at a "
                              "corner of three or more creases or on a boundary, or make it semi-sharp (sharpness "
                              "below " + below + ")");
    }
    const bool corner = sharp > 2 || topology.vertexFaces(v).size() == 1;
    for (const std::vector<int>& sector : topology.sharpSectors(v)) {
      if (corner && sector.size() != 1) {
        throw Error(source, at + "a corner of " + std::to_string(sharp) + " sharp edges with " +
                                std::to_string(sector.size()) +
                                " faces between two of them is not supported (one face is)");
      }
      if (!corner && sector.size() < 2) {
        throw Error(source, at + "a sharp crease with a single face on one side is not supported (two or more are)");
      }
    }
  }
}

}  // namespace dynsub
