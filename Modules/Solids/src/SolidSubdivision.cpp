#include "dynsub/SolidSubdivision.h"

#include <algorithm>
#include <map>

#include "dynsub/Error.h"

namespace dynsub {

namespace {

// Rows of A as weights on the old points, accumulated element by element.
class Rows {
 public:
  explicit Rows(int rows) : rows_(rows) {}
  void add(int r, int p, double w) { triplets_.emplace_back(r, p, w); }
  // Row `r` += w * row `source` of the rows built so far (`source` complete).
  void addRow(int r, const std::vector<Eigen::Triplet<double>>& sourceRow, double w) {
    for (const auto& t : sourceRow) triplets_.emplace_back(r, t.col(), w * t.value());
  }
  SparseMatrix matrix(int columns) const {
    SparseMatrix A(rows_, columns);
    A.setFromTriplets(triplets_.begin(), triplets_.end());
    return A;
  }

 private:
  int rows_;
  std::vector<Eigen::Triplet<double>> triplets_;
};

using Row = std::vector<Eigen::Triplet<double>>;

Row averageRow(const std::vector<int>& points) {
  Row row;
  for (int p : points) row.emplace_back(0, p, 1.0 / points.size());
  return row;
}

// What the rules average: each face's and cell's centroid as a row of
// weights on the old points, and how many boundary faces each edge has.
struct Centroids {
  std::vector<Row> face, cell;
  std::vector<int> boundaryFacesOfEdge;
};

Centroids centroidsOf(const Lattice& l) {
  Centroids c;
  for (int f = 0; f < l.faceCount(); ++f) c.face.push_back(averageRow(l.faces()[f]));
  for (int k = 0; k < l.cellCount(); ++k) c.cell.push_back(averageRow(l.cellPoints()[k]));
  c.boundaryFacesOfEdge.assign(l.edgeCount(), 0);
  for (int f = 0; f < l.faceCount(); ++f)
    if (l.isBoundaryFace(f))
      for (int e : l.faceEdges()[f]) ++c.boundaryFacesOfEdge[e];
  return c;
}

// The rows of the new cell and face points.
void addCellAndFacePoints(const Lattice& l, const Centroids& centroids, Rows& rows) {
  const int P = l.pointCount(), E = l.edgeCount(), F = l.faceCount(), C = l.cellCount();
  const int faceStart = P + E, cellStart = P + E + F;
  const std::vector<Row>& faceCentroid = centroids.face;
  const std::vector<Row>& cellCentroid = centroids.cell;
  // Cell points.
  for (int c = 0; c < C; ++c) rows.addRow(cellStart + c, cellCentroid[c], 1.0);
  // Face points.
  for (int f = 0; f < F; ++f) {
    if (l.isBoundaryFace(f)) {
      rows.addRow(faceStart + f, faceCentroid[f], 1.0);
    } else {
      rows.addRow(faceStart + f, faceCentroid[f], 0.5);
      for (int c : l.faceCells()[f]) rows.addRow(faceStart + f, cellCentroid[c], 0.25);
    }
  }
}

// The rows of the new edge points: interior, on the boundary, on a crease.
void addEdgePoints(const Lattice& l, const Centroids& centroids, Rows& rows) {
  const int E = l.edgeCount();
  const int edgeStart = l.pointCount();
  const std::vector<Row>& faceCentroid = centroids.face;
  const std::vector<Row>& cellCentroid = centroids.cell;
  const std::vector<int>& boundaryFacesOfEdge = centroids.boundaryFacesOfEdge;
  // Edge points.
  for (int e = 0; e < E; ++e) {
    const int r = edgeStart + e;
    const auto [a, b] = l.edges()[e];
    if (boundaryFacesOfEdge[e] == 0) {
      const auto& faces = l.edgeFaces()[e];
      const auto& cells = l.edgeCells()[e];
      const double n = faces.size();
      for (int c : cells) rows.addRow(r, cellCentroid[c], 1.0 / (n * cells.size()));
      for (int f : faces) rows.addRow(r, faceCentroid[f], 2.0 / (n * faces.size()));
      rows.add(r, a, 0.5 * (n - 3.0) / n);
      rows.add(r, b, 0.5 * (n - 3.0) / n);
    } else if (boundaryFacesOfEdge[e] == 2) {
      rows.add(r, a, 0.25);
      rows.add(r, b, 0.25);
      for (int f : l.edgeFaces()[e])
        if (l.isBoundaryFace(f)) rows.addRow(r, faceCentroid[f], 0.25);
    } else {  // a crease of the boundary
      rows.add(r, a, 0.5);
      rows.add(r, b, 0.5);
    }
  }
}

// The rows of the new vertex points: interior, on a crease, on the boundary.
void addVertexPoints(const Lattice& l, const Centroids& centroids, Rows& rows) {
  const int P = l.pointCount();
  const std::vector<Row>& faceCentroid = centroids.face;
  const std::vector<Row>& cellCentroid = centroids.cell;
  const std::vector<int>& boundaryFacesOfEdge = centroids.boundaryFacesOfEdge;
  // Vertex points.
  for (int p = 0; p < P; ++p) {
    std::vector<int> boundaryFaces, boundaryEdges;
    for (int f : l.pointFaces()[p])
      if (l.isBoundaryFace(f)) boundaryFaces.push_back(f);
    bool crease = false;
    for (int e : l.pointEdges()[p]) {
      if (boundaryFacesOfEdge[e] == 0) continue;
      boundaryEdges.push_back(e);
      crease = crease || boundaryFacesOfEdge[e] != 2;
    }
    if (boundaryFaces.empty()) {
      const auto& cells = l.pointCells()[p];
      const auto& faces = l.pointFaces()[p];
      const auto& edges = l.pointEdges()[p];
      for (int c : cells) rows.addRow(p, cellCentroid[c], 1.0 / (8.0 * cells.size()));
      for (int f : faces) rows.addRow(p, faceCentroid[f], 3.0 / (8.0 * faces.size()));
      for (int e : edges) {
        rows.add(p, l.edges()[e][0], 1.5 / (8.0 * edges.size()));
        rows.add(p, l.edges()[e][1], 1.5 / (8.0 * edges.size()));
      }
      rows.add(p, p, 1.0 / 8.0);
    } else if (crease) {
      rows.add(p, p, 1.0);
    } else {
      const double n = boundaryEdges.size();
      for (int f : boundaryFaces) rows.addRow(p, faceCentroid[f], 1.0 / (n * boundaryFaces.size()));
      for (int e : boundaryEdges) {
        rows.add(p, l.edges()[e][0], 1.0 / (n * n));
        rows.add(p, l.edges()[e][1], 1.0 / (n * n));
      }
      rows.add(p, p, (n - 3.0) / n);
    }
  }
}

// The refined lattice's faces (each old face's quads, then the faces inside
// each old cell) and cells (one per old cell and corner).
struct RefinedTopology {
  std::vector<std::vector<int>> faces, cells;
};

RefinedTopology refinedTopology(const Lattice& l) {
  const int P = l.pointCount(), E = l.edgeCount(), F = l.faceCount(), C = l.cellCount();
  const int edgeStart = P, faceStart = P + E, cellStart = P + E + F;
  // Topology of the refined lattice.
  std::vector<int> faceOffset(F + 1, 0);  // first sub-face of each old face
  for (int f = 0; f < F; ++f) faceOffset[f + 1] = faceOffset[f] + static_cast<int>(l.faces()[f].size());
  std::vector<std::vector<int>> faces;
  faces.reserve(faceOffset[F]);
  for (int f = 0; f < F; ++f) {
    const auto& loop = l.faces()[f];
    const auto& fe = l.faceEdges()[f];
    const int n = static_cast<int>(loop.size());
    for (int i = 0; i < n; ++i)  // the quad at corner loop[i], in the face's orientation
      faces.push_back({loop[i], edgeStart + fe[i], faceStart + f, edgeStart + fe[(i + n - 1) % n]});
  }
  std::map<std::pair<int, int>, int> innerFace;  // (cell, edge) -> face inside the cell
  for (int c = 0; c < C; ++c) {
    for (int e : l.cellEdges()[c]) {
      int fa = -1, fb = -1;
      for (int f : l.cells()[c]) {
        for (int fe : l.faceEdges()[f])
          if (fe == e) (fa < 0 ? fa : fb) = f;
      }
      innerFace[{c, e}] = static_cast<int>(faces.size());
      faces.push_back({edgeStart + e, faceStart + fa, cellStart + c, faceStart + fb});
    }
  }
  std::vector<std::vector<int>> cells;
  for (int c = 0; c < C; ++c) {
    for (int p : l.cellPoints()[c]) {
      std::vector<int> shell;
      for (int f : l.cells()[c]) {
        const auto& loop = l.faces()[f];
        for (std::size_t i = 0; i < loop.size(); ++i)
          if (loop[i] == p) shell.push_back(faceOffset[f] + static_cast<int>(i));
      }
      for (int e : l.pointEdges()[p])
        if (innerFace.count({c, e})) shell.push_back(innerFace.at({c, e}));
      cells.push_back(std::move(shell));
    }
  }
  return {std::move(faces), std::move(cells)};
}

}  // namespace

SolidRefinement subdivideSolid(const Lattice& l) {
  const Centroids centroids = centroidsOf(l);
  Rows rows(l.pointCount() + l.edgeCount() + l.faceCount() + l.cellCount());
  addCellAndFacePoints(l, centroids, rows);
  addEdgePoints(l, centroids, rows);
  addVertexPoints(l, centroids, rows);
  RefinedTopology topology = refinedTopology(l);

  SolidRefinement refined;
  for (int f = 0; f < l.faceCount(); ++f) refined.faceOrigin.insert(refined.faceOrigin.end(), l.faces()[f].size(), f);
  refined.faceOrigin.resize(topology.faces.size(), -1);
  for (int c = 0; c < l.cellCount(); ++c)
    refined.cellOrigin.insert(refined.cellOrigin.end(), l.cellPoints()[c].size(), c);
  refined.A = rows.matrix(l.pointCount());
  const MatrixX3 points = refined.A * l.points();
  refined.lattice =
      Lattice::fromCells(points, std::move(topology.faces), std::move(topology.cells), "subdivided lattice");
  return refined;
}

SolidRefinement subdivideSolid(const Lattice& lattice, int levels) {
  if (levels < 0) throw Error("the subdivision level must be >= 0 (got " + std::to_string(levels) + ")");
  SolidRefinement result{lattice, SparseMatrix(lattice.pointCount(), lattice.pointCount()), {}, {}};
  result.A.setIdentity();
  for (int f = 0; f < lattice.faceCount(); ++f) result.faceOrigin.push_back(f);
  for (int c = 0; c < lattice.cellCount(); ++c) result.cellOrigin.push_back(c);
  for (int level = 0; level < levels; ++level) {
    SolidRefinement next = subdivideSolid(result.lattice);
    result.A = (next.A * result.A).pruned();
    result.lattice = std::move(next.lattice);
    for (int& f : next.faceOrigin)
      if (f >= 0) f = result.faceOrigin[f];
    for (int& c : next.cellOrigin) c = result.cellOrigin[c];
    result.faceOrigin = std::move(next.faceOrigin);
    result.cellOrigin = std::move(next.cellOrigin);
  }
  return result;
}

LatticeCounts refinedCounts(const Lattice& lattice, int levels) {
  LatticeCounts n{static_cast<std::uint64_t>(lattice.pointCount()), static_cast<std::uint64_t>(lattice.edgeCount()),
                  static_cast<std::uint64_t>(lattice.faceCount()), static_cast<std::uint64_t>(lattice.cellCount())};
  // Sums over faces of their points, and over cells of their faces and edges.
  std::uint64_t faceCorners = 0, cellFaces = 0, cellEdges = 0;
  for (const auto& face : lattice.faces()) faceCorners += face.size();
  for (const auto& cell : lattice.cells()) cellFaces += cell.size();
  // (cell, corner) pairs by the number k of the cell's edges at the corner.
  std::map<std::uint64_t, std::uint64_t> corners;
  for (int c = 0; c < lattice.cellCount(); ++c) {
    cellEdges += lattice.cellEdges()[c].size();
    for (int p : lattice.cellPoints()[c]) {
      const auto& edges = lattice.cellEdges()[c];
      ++corners[std::count_if(edges.begin(), edges.end(),
                              [&](int e) { return lattice.edges()[e][0] == p || lattice.edges()[e][1] == p; })];
    }
  }
  for (int level = 0; level < levels; ++level) {
    LatticeCounts next;
    next.points = n.points + n.edges + n.faces + n.cells;
    next.edges = 2 * n.edges + faceCorners + cellFaces;
    next.faces = faceCorners + cellEdges;
    next.cells = 0;
    std::map<std::uint64_t, std::uint64_t> nextCorners;
    cellFaces = cellEdges = 0;
    for (const auto& [k, count] : corners) {
      next.cells += count;
      cellFaces += 2 * k * count;
      cellEdges += 4 * k * count;
      nextCorners[k] += 2 * count;
      nextCorners[3] += 2 * k * count;
    }
    faceCorners = 4 * next.faces;
    corners = nextCorners;
    n = next;
  }
  return n;
}

}  // namespace dynsub
