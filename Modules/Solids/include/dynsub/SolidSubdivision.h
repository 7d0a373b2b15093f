#pragma once
// Catmull-Clark solid subdivision (McDonnell and Qin §3.1; MacCracken and
// Joy's volumetric extension of Catmull-Clark) as a linear map d = A p (§4.1):
// every refined point is a fixed affine blend of the lattice's points.
//
// Rules for elements inside the solid (the paper's):
//   cell point    c = the cell's centroid (average of its distinct points);
//   face point    f = (c0 + 2 a + c1) / 4, a the face centroid, c0 and c1 the
//                 centroids of its two cells;
//   edge point    e = (c_avg + 2 a_avg + (n - 3) m) / n over the n faces and
//                 the cells around the edge, m its midpoint;
//   vertex point  v = (c_avg + 3 a_avg + 3 m_avg + p) / 8 over the cells,
//                 faces and edges at p.
// On the boundary (faces of one cell, and the edges and points on them) the
// rules are Catmull-Clark's surface rules applied to the boundary faces:
//   face point    f = a;
//   edge point    e = (v0 + v1 + a0 + a1) / 4 over its two boundary faces;
//   vertex point  v = (Q + 2 R + (n - 3) p) / n, Q the average centroid of
//                 the boundary faces at p, R the average midpoint of its n
//                 boundary edges.
// So the solid's boundary surface is exactly the Catmull-Clark surface of the
// lattice's boundary faces, and a regular interior is a tri-cubic B-spline
// solid. Where the boundary itself is not a closed surface (an edge on other
// than two boundary faces: a crease), the edge point is the midpoint and its
// end points stay where they are.
//
// Refined lattice: points are numbered [vertex points | edge points | face
// points | cell points] in the order of the elements they come from. A face of
// n points gives n quads; each edge of a cell gives a quad (edge point, face
// point, cell point, face point) inside the cell; each point of a cell gives a
// new cell. Counts: P' = P + E + F + C, F' = sum n_f + sum_c E_c,
// C' = sum_c P_c.
#include <cstdint>

#include "dynsub/Lattice.h"

namespace dynsub {

struct SolidRefinement {
  Lattice lattice;
  SparseMatrix A;  // #refined points x #points: refined = A * points
  // Where each refined face and cell lies in the lattice it came from: the
  // face it is part of (-1 for a face inside a cell), and the cell it is part
  // of. Picking a refined face or cell finds the control element to sculpt.
  std::vector<int> faceOrigin, cellOrigin;
};

SolidRefinement subdivideSolid(const Lattice& lattice);
// `levels` >= 0 refinements; A is their product (#points at the last level x #points).
SolidRefinement subdivideSolid(const Lattice& lattice, int levels);

// The counts of `levels` refinements of `lattice`, from its incidences
// alone. A cell's corner where k of its edges meet refines into a cell of
// 2k + 2 points, 4k edges and 2k faces, two of whose corners have k edges and
// the rest 3; so the counts of (cell, corner) pairs by k carry the sums above
// from level to level, and a level 6 is counted without building it.
struct LatticeCounts {
  std::uint64_t points = 0, edges = 0, faces = 0, cells = 0;
};
LatticeCounts refinedCounts(const Lattice& lattice, int levels);

}  // namespace dynsub
