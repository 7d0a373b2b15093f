#include "PatchRules.h"

#include <algorithm>
#include <cmath>

#include "dynsub/CatmullClark.h"
#include "dynsub/Error.h"

namespace dynsub::detail {

namespace {

constexpr int slot(int i, int j) { return i + 4 * j; }

// 2 a - b: the ghost that mirrors b through a.
SmallStencil mirror(const SmallStencil& a, const SmallStencil& b) {
  SmallStencil result;
  for (const auto& [v, w] : a) result.emplace_back(v, 2.0 * w);
  for (const auto& [v, w] : b) result.emplace_back(v, -w);
  return result;
}

}  // namespace

bool gatherRegularPatch(const Topology& topology, int face, std::array<SmallStencil, 16>& grid) {
  if (topology.faceSize(face) != 4) return false;
  const Polygon& q = topology.face(face);
  for (int v : q) {
    if (!topology.isRegularVertex(v)) return false;
  }
  // Slots of the outer neighbours along side k (edge q[k] -> q[k+1]): the one
  // next to q[k], the one next to q[k+1]; and the diagonal slot at corner k.
  static constexpr int nearSlot[4] = {slot(1, 0), slot(3, 1), slot(2, 3), slot(0, 2)};
  static constexpr int farSlot[4] = {slot(2, 0), slot(3, 2), slot(1, 3), slot(0, 1)};
  static constexpr int diagonalSlot[4] = {slot(0, 0), slot(3, 0), slot(3, 3), slot(0, 3)};

  std::array<int, 16> vertex;
  vertex.fill(-1);
  vertex[slot(1, 1)] = q[0];
  vertex[slot(2, 1)] = q[1];
  vertex[slot(2, 2)] = q[2];
  vertex[slot(1, 2)] = q[3];
  bool side[4];
  for (int k = 0; k < 4; ++k) {
    const int neighbour = topology.otherFace(topology.faceEdge(face, k), face);
    side[k] = neighbour >= 0;
    if (!side[k]) continue;
    if (topology.faceSize(neighbour) != 4) return false;
    const Polygon& g = topology.face(neighbour);
    // The neighbour runs q[k+1] -> q[k] -> x -> y.
    const int c = topology.corner(neighbour, q[(k + 1) % 4]);
    const int x = g[(c + 2) % 4];
    vertex[nearSlot[k]] = x;
    vertex[farSlot[k]] = g[(c + 3) % 4];
    // The diagonal face at q[k] lies across the edge (q[k], x) from the neighbour.
    const int diagonal = topology.otherFace(topology.findEdge(q[k], x), neighbour);
    if (diagonal >= 0) {
      if (topology.faceSize(diagonal) != 4) return false;
      vertex[diagonalSlot[k]] = topology.face(diagonal)[(topology.corner(diagonal, q[k]) + 2) % 4];
    }
  }
  for (int s = 0; s < 16; ++s) {
    grid[s].clear();
    if (vertex[s] >= 0) grid[s].emplace_back(vertex[s], 1.0);
  }
  // Ghost rows and columns across boundary sides.
  if (!side[0]) {
    for (int i : {1, 2}) grid[slot(i, 0)] = mirror(grid[slot(i, 1)], grid[slot(i, 2)]);
  }
  if (!side[1]) {
    for (int j : {1, 2}) grid[slot(3, j)] = mirror(grid[slot(2, j)], grid[slot(1, j)]);
  }
  if (!side[2]) {
    for (int i : {1, 2}) grid[slot(i, 3)] = mirror(grid[slot(i, 2)], grid[slot(i, 1)]);
  }
  if (!side[3]) {
    for (int j : {1, 2}) grid[slot(0, j)] = mirror(grid[slot(1, j)], grid[slot(2, j)]);
  }
  // Ghost corners: mirrored across the missing side (either, for a corner
  // vertex with both sides missing: the results agree).
  struct CornerRule {
    int target;
    int verticalSide, verticalA, verticalB;      // mirror along v if this side is missing
    int horizontalSide, horizontalA, horizontalB;  // else along u if this one is
  };
  static constexpr CornerRule corners[4] = {
      {slot(0, 0), 0, slot(0, 1), slot(0, 2), 3, slot(1, 0), slot(2, 0)},
      {slot(3, 0), 0, slot(3, 1), slot(3, 2), 1, slot(2, 0), slot(1, 0)},
      {slot(3, 3), 2, slot(3, 2), slot(3, 1), 1, slot(2, 3), slot(1, 3)},
      {slot(0, 3), 2, slot(0, 2), slot(0, 1), 3, slot(1, 3), slot(2, 3)},
  };
  for (const CornerRule& rule : corners) {
    if (!grid[rule.target].empty()) continue;
    if (!side[rule.verticalSide]) {
      grid[rule.target] = mirror(grid[rule.verticalA], grid[rule.verticalB]);
    } else if (!side[rule.horizontalSide]) {
      grid[rule.target] = mirror(grid[rule.horizontalA], grid[rule.horizontalB]);
    } else {
      return false;  // both sides present but no diagonal: not a regular corner
    }
  }
  return true;
}

Eigen::Matrix<double, 6, 16> bsplineWeights(double u, double v) {
  auto basis = [](double t, double b[4], double d[4], double dd[4]) {
    const double s = 1.0 - t;
    b[0] = s * s * s / 6.0;
    b[1] = (3.0 * t * t * t - 6.0 * t * t + 4.0) / 6.0;
    b[2] = (-3.0 * t * t * t + 3.0 * t * t + 3.0 * t + 1.0) / 6.0;
    b[3] = t * t * t / 6.0;
    d[0] = -0.5 * s * s;
    d[1] = 1.5 * t * t - 2.0 * t;
    d[2] = -1.5 * t * t + t + 0.5;
    d[3] = 0.5 * t * t;
    dd[0] = s;
    dd[1] = 3.0 * t - 2.0;
    dd[2] = -3.0 * t + 1.0;
    dd[3] = t;
  };
  double bu[4], du[4], ddu[4], bv[4], dv[4], ddv[4];
  basis(u, bu, du, ddu);
  basis(v, bv, dv, ddv);
  Eigen::Matrix<double, 6, 16> w;
  for (int j = 0; j < 4; ++j) {
    for (int i = 0; i < 4; ++i) {
      const int s = slot(i, j);
      w(0, s) = bu[i] * bv[j];
      w(1, s) = du[i] * bv[j];
      w(2, s) = bu[i] * dv[j];
      w(3, s) = ddu[i] * bv[j];
      w(4, s) = du[i] * dv[j];
      w(5, s) = bu[i] * ddv[j];
    }
  }
  return w;
}

VertexMasks vertexMasks(const Topology& topology, int x, int f) {
  const int faceLimit = static_cast<int>(topology.vertexFaces(x).size());
  // Around x counter-clockwise: in face g (x, a, c, b) the fan goes from edge
  // x-a to edge x-b; the next face lies across x-b, the previous across x-a.
  auto step = [&](int g, int offset) {
    const int c = topology.corner(g, x);
    const int w = topology.face(g)[(c + offset) % 4];
    return topology.otherFace(topology.findEdge(x, w), g);
  };
  int start = f;
  const bool boundary = topology.isBoundaryVertex(x);
  if (boundary) {
    for (int guard = 0; guard < faceLimit; ++guard) {
      const int previous = step(start, 1);
      if (previous < 0) break;
      start = previous;
    }
  }
  std::vector<int> edgeNeighbour, opposite;
  int position = -1;  // index of f in the fan
  int g = start;
  for (int guard = 0; guard < faceLimit && g >= 0; ++guard) {
    if (g == f) position = static_cast<int>(edgeNeighbour.size());
    const int c = topology.corner(g, x);
    edgeNeighbour.push_back(topology.face(g)[(c + 1) % 4]);
    opposite.push_back(topology.face(g)[(c + 2) % 4]);
    const int next = step(g, 3);
    if (boundary && next < 0) edgeNeighbour.push_back(topology.face(g)[(c + 3) % 4]);
    g = next;
    if (g == start) break;
  }
  if (position < 0) throw Error("internal: face " + std::to_string(f) + " is not around vertex " + std::to_string(x));

  VertexMasks masks;
  const int n = static_cast<int>(opposite.size());  // faces around x
  if (!boundary) {
    // Interior: limit (n^2 x + 4 sum e_i + sum d_i) / (n (n + 5)), tangents of
    // Halstead et al.; index i counts from f's edge x-a.
    masks.position.emplace_back(x, static_cast<double>(n) / (n + 5));
    const double nn = static_cast<double>(n) * (n + 5);
    const double a = 1.0 + std::cos(2.0 * M_PI / n) +
                     std::cos(M_PI / n) * std::sqrt(2.0 * (9.0 + std::cos(2.0 * M_PI / n)));
    const double scale = 4.0 / (3.0 * n * a);  // equals the B-spline derivative for n = 4
    for (int k = 0; k < n; ++k) {
      const int i = (k - position + n) % n;
      masks.position.emplace_back(edgeNeighbour[k], 4.0 / nn);
      masks.position.emplace_back(opposite[k], 1.0 / nn);
      auto angle = [n](int j) { return std::cos(2.0 * M_PI * j / n); };
      masks.tangentU.emplace_back(edgeNeighbour[k], scale * a * angle(i));
      masks.tangentU.emplace_back(opposite[k], scale * (angle(i) + angle(i + 1)));
      masks.tangentV.emplace_back(edgeNeighbour[k], scale * a * angle(i - 1));
      masks.tangentV.emplace_back(opposite[k], scale * (angle(i - 1) + angle(i)));
    }
    return masks;
  }
  const int first = edgeNeighbour.front();
  const int last = edgeNeighbour.back();
  if (n == 1) {
    // A corner is interpolated; the limit surface's edges leave it along the
    // control polygon's edges, with derivative e - x (cubic B-spline end).
    masks.position.emplace_back(x, 1.0);
    masks.tangentU = {{first, 1.0}, {x, -1.0}};
    masks.tangentV = {{last, 1.0}, {x, -1.0}};
    return masks;
  }
  masks.position = {{x, 4.0 / 6.0}, {first, 1.0 / 6.0}, {last, 1.0 / 6.0}};
  masks.boundary = true;
  masks.faces = n;
  masks.fanPosition = position;
  masks.along = {{first, 0.5}, {last, -0.5}};
  return masks;
}

Neighbourhood extractNeighbourhood(const Topology& topology, int x, int f) {
  std::vector<int> faces;  // sorted: the set of faces to take
  for (int g : topology.vertexFaces(x)) {
    for (int w : topology.face(g)) {
      for (int h : topology.vertexFaces(w)) faces.push_back(h);
    }
  }
  std::sort(faces.begin(), faces.end());
  faces.erase(std::unique(faces.begin(), faces.end()), faces.end());
  auto indexOf = [&](int g) {
    const auto it = std::lower_bound(faces.begin(), faces.end(), g);
    return it != faces.end() && *it == g ? static_cast<int>(it - faces.begin()) : -1;
  };

  // The faces are ordered breadth-first across edges from f, each rotated
  // to begin where it was entered, and vertices numbered as first met. The
  // order then depends only on the mesh's structure around x, not on its
  // global numbering, so equal neighbourhoods (around every extraordinary
  // vertex of one valence in otherwise regular surroundings, and around all
  // of them after a level of subdivision) have equal local topologies, and
  // LimitSurface shares their subdivision steps.
  std::vector<std::pair<int, int>> order;  // (face, first corner)
  order.reserve(faces.size());
  std::vector<char> taken(faces.size(), 0);
  order.emplace_back(f, topology.corner(f, x));
  taken[indexOf(f)] = 1;
  for (size_t next = 0; next < order.size(); ++next) {
    const auto [g, first] = order[next];
    const int n = topology.faceSize(g);
    for (int k = 0; k < n; ++k) {
      const int corner = (first + k) % n;
      const int h = topology.otherFace(topology.faceEdge(g, corner), g);
      const int index = h < 0 ? -1 : indexOf(h);
      if (index < 0 || taken[index]) continue;
      taken[index] = 1;
      // h runs along the shared edge the other way: it is entered at g's next corner.
      order.emplace_back(h, topology.corner(h, topology.face(g)[(corner + 1) % n]));
    }
  }
  // Faces not reached across edges (none in a manifold mesh) keep their order.
  for (size_t i = 0; i < faces.size(); ++i) {
    if (!taken[i]) order.emplace_back(faces[i], 0);
  }

  Neighbourhood result;
  result.face = 0;
  result.faces.reserve(order.size());
  for (const auto& [g, first] : order) {
    Polygon polygon = topology.face(g);
    std::rotate(polygon.begin(), polygon.begin() + first, polygon.end());
    for (int& v : polygon) {
      // A neighbourhood has a few dozen vertices: a scan finds one sooner
      // than a hash map is built.
      const auto it = std::find(result.parentVertex.begin(), result.parentVertex.end(), v);
      const int local = static_cast<int>(it - result.parentVertex.begin());
      if (it == result.parentVertex.end()) result.parentVertex.push_back(v);
      v = local;
    }
    result.faces.push_back(std::move(polygon));
  }
  return result;
}

CornerStep cornerStep(std::shared_ptr<const Topology> from, int face) {
  const Topology& topology = *from;
  const Refinement refinement = refine(topology);
  const Eigen::MatrixXd refined = Eigen::MatrixXd(refinement.subdivisionMatrix);  // refined <- local
  const int firstChild = refinement.childFaceOffset[face];
  CornerStep step;
  step.from = std::move(from);
  step.face = face;
  std::array<SmallStencil, 16> grid;
  for (int k = 1; k <= 3; ++k) {
    if (!gatherRegularPatch(refinement.topology, firstChild + k, grid)) {
      throw Error("internal: subpatch " + std::to_string(k) + " next to an extraordinary vertex is not regular");
    }
    Eigen::MatrixXd& patch = step.patches[k - 1];
    patch.setZero(16, refined.cols());
    for (int s = 0; s < 16; ++s) {
      for (const auto& [v, w] : grid[s]) patch.row(s) += w * refined.row(v);
    }
  }
  // The vertex point of the extraordinary vertex keeps its index, and child 0
  // has it as corner 0.
  const int x = topology.face(face)[0];
  Neighbourhood next = extractNeighbourhood(refinement.topology, x, firstChild);
  step.next = refined(next.parentVertex, Eigen::all);
  step.to = std::make_shared<const Topology>(static_cast<int>(next.parentVertex.size()), std::move(next.faces));
  step.toFace = next.face;
  return step;
}

LevelPatches subdivideAroundCorner(LocalMesh& mesh, const CornerStep& step) {
  if (step.face != mesh.face || (step.from != mesh.topology && step.from->faces() != mesh.topology->faces())) {
    throw Error("internal: a local subdivision step applied to another neighbourhood");
  }
  LevelPatches patches;
  for (int k = 0; k < 3; ++k) patches[k].noalias() = step.patches[k] * mesh.weights;
  mesh.weights = step.next * mesh.weights;
  mesh.topology = step.to;
  mesh.face = step.toFace;
  return patches;
}

std::pair<double, double> cornerFrame(int k, double u, double v) {
  switch (k) {
    case 0: return {u, v};
    case 1: return {v, 1.0 - u};
    case 2: return {1.0 - u, 1.0 - v};
    default: return {1.0 - v, u};
  }
}

Eigen::Matrix2d cornerFrameJacobian(int k) {
  Eigen::Matrix2d m;
  switch (k) {
    case 0: m << 1, 0, 0, 1; break;
    case 1: m << 0, 1, -1, 0; break;
    case 2: m << -1, 0, 0, -1; break;
    default: m << 0, -1, 1, 0; break;
  }
  return m;
}

}  // namespace dynsub::detail
