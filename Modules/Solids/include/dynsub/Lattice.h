#pragma once
// A control lattice of a Catmull-Clark subdivision solid (McDonnell and Qin,
// "Dynamic sculpting and animation of free-form subdivision solids", §3.1,
// §5.3): points, edges, faces and cells with full adjacency, in the manner of
// a radial-edge structure: from any point, edge, face or cell one finds the
// elements it is made of and the elements it belongs to.
//
// A face is a loop of distinct points (>= 3); a cell is a closed shell of
// faces. Edges are derived from the faces. A face belongs to one cell (a
// boundary face: it lies on the solid's surface) or two (an interior face).
//
// Validity (checked by fromCells, which throws dynsub::Error naming `source`
// and the element at fault):
//  - indices in range, no repeated point in a face, no repeated face in a cell;
//  - every face belongs to at least one cell (no dangling face) and at most two;
//  - every cell is closed: each edge of its faces lies in exactly two of them.
#include <array>
#include <string>
#include <vector>

#include "dynsub/Types.h"

namespace dynsub {

class Lattice {
 public:
  Lattice() = default;

  static Lattice fromCells(MatrixX3 points, std::vector<std::vector<int>> faces, std::vector<std::vector<int>> cells,
                           const std::string& source = "lattice");

  int pointCount() const { return static_cast<int>(points_.rows()); }
  int edgeCount() const { return static_cast<int>(edges_.size()); }
  int faceCount() const { return static_cast<int>(faces_.size()); }
  int cellCount() const { return static_cast<int>(cells_.size()); }

  const MatrixX3& points() const { return points_; }  // #points x 3, mm
  // Replaces the positions; same number of rows, finite.
  void setPoints(const MatrixX3& points);

  // What elements are made of.
  const std::vector<std::array<int, 2>>& edges() const { return edges_; }  // (a, b), a < b
  const std::vector<std::vector<int>>& faces() const { return faces_; }    // point loops
  const std::vector<std::vector<int>>& cells() const { return cells_; }    // face lists
  // Edge i of a face joins loop point i and loop point i + 1.
  const std::vector<std::vector<int>>& faceEdges() const { return faceEdges_; }
  const std::vector<std::vector<int>>& cellEdges() const { return cellEdges_; }    // distinct, sorted
  const std::vector<std::vector<int>>& cellPoints() const { return cellPoints_; }  // distinct, sorted

  // What elements belong to.
  const std::vector<std::vector<int>>& faceCells() const { return faceCells_; }  // 1 or 2
  const std::vector<std::vector<int>>& edgeFaces() const { return edgeFaces_; }
  const std::vector<std::vector<int>>& edgeCells() const { return edgeCells_; }
  const std::vector<std::vector<int>>& pointEdges() const { return pointEdges_; }
  const std::vector<std::vector<int>>& pointFaces() const { return pointFaces_; }
  const std::vector<std::vector<int>>& pointCells() const { return pointCells_; }

  bool isBoundaryFace(int face) const { return faceCells_[face].size() == 1; }
  // The edge joining two points, or -1.
  int edgeBetween(int a, int b) const;

 private:
  MatrixX3 points_;
  std::vector<std::array<int, 2>> edges_;
  std::vector<std::vector<int>> faces_, cells_, faceEdges_, cellEdges_, cellPoints_;
  std::vector<std::vector<int>> faceCells_, edgeFaces_, edgeCells_, pointEdges_, pointFaces_, pointCells_;
};

// The sculpting tools' changes of topology (§5.4); both return a new valid
// lattice. Throws dynsub::Error naming the face or cell when the tool does
// not apply.
//  - extrudeFace: a new cell on a boundary face, grown along the face's
//    outward normal by twice the distance from the face's centroid to its
//    cell's centroid (the cell's own depth there). The lattice's points,
//    faces and cells keep their numbers; the new ones follow, the new cell's
//    outer face (opposite `face`) first.
//  - deleteCell: the cell and every face, edge and point only it used go
//    (not the last cell). `kept` (if given) receives the new number of each
//    old point, or -1 for a removed one. The faces it shared come to the
//    surface turned counter-clockwise seen from outside.
Lattice extrudeFace(const Lattice& lattice, int face);
// The average of the rows `indices` of `points` (a face's or a cell's centre).
Vector3 centroidOf(const MatrixX3& points, const std::vector<int>& indices);

// Whether `face` runs counter-clockwise seen from outside `cell` (its Newell
// normal points away from the cell's centroid): how a boundary face should run
// with `cell` its cell.
bool facesAwayFrom(const Lattice& lattice, int face, int cell);
Lattice deleteCell(const Lattice& lattice, int cell, std::vector<int>* kept = nullptr);

// A regular lattice of nx x ny x nz hexahedral cells of side `size` (mm),
// (nx + 1)(ny + 1)(nz + 1) points numbered x fastest, from the origin;
// the cells listed in `removed` (as x + nx (y + ny z)) are left out (their
// points stay if other cells use them; unused points are an error).
Lattice regularLattice(int nx, int ny, int nz, double size = 1.0, const std::vector<int>& removed = {});

}  // namespace dynsub
