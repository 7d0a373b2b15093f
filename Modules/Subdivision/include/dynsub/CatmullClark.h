#pragma once
// One global Catmull-Clark step (TVCG 1998 §2.1; Catmull and Clark 1978) on a
// polygon mesh of any topology, with the sparse subdivision matrix A such that
// refined vertex positions = A * old vertex positions (#refined by #old; every
// row sums to 1).
//
// Rules. Face point: the average of the face's vertices. Interior edge point:
// the average of the edge's ends and the two adjacent face points. Interior
// vertex of n edges: (F + 2R + (n-3)V)/n, with F the average of the adjacent
// face points and R of the incident edge midpoints. Boundaries (the standard
// rules, so a boundary converges to the cubic B-spline of its polygon):
// boundary edge point = the edge midpoint; boundary vertex = 1/8, 3/4, 1/8 of
// its two boundary neighbours and itself; a corner (one face) stays fixed.
//
// Creases (DeRose, Kass and Truong 1998, with OpenSubdiv's rules, which its
// oracle tests check): an edge of sharpness >= 1 gets the boundary's edge rule,
// one of sharpness s in (0, 1) the blend s midpoint + (1 - s) smooth point. A
// vertex with two sharp edges (boundary edges count) gets the boundary vertex
// rule along them, with more it stays fixed, with fewer (a dart) it is smooth.
// Where a sharpness decays to 0 in the step, the vertex's rules before and
// after are blended by the decaying sharpnesses' mean. The refined edges carry
// childSharpness() of their parent's.
//
// Numbering of the refined mesh: vertex points first (old vertex i stays vertex
// i), then edge points (#vertices + edge), then face points (#vertices + #edges
// + face). An n-gon f becomes n quads, child k = (vertex point of corner k,
// edge point of edge k, face point, edge point of edge k-1), numbered
// childFaceOffset[f] + k: child k's corner 0 is old corner k.
#include <vector>

#include "dynsub/ControlMesh.h"
#include "dynsub/Topology.h"
#include "dynsub/Types.h"

namespace dynsub {

struct Refinement {
  Topology topology;
  SparseMatrix subdivisionMatrix;    // A: #refined vertices by #old vertices
  std::vector<int> childFaceOffset;  // first child of each old face
};

Refinement refine(const Topology& topology);

// A refined half-edge's sharpness: s - 1 for a semi-sharp edge (0 once s <= 1),
// unchanged from kInfiniteSharpness up.
double childSharpness(double sharpness);

// A control mesh refined once: mesh.points() == subdivisionMatrix * old points,
// and its limit surface is the old one.
struct SubdividedMesh {
  ControlMesh mesh;
  SparseMatrix subdivisionMatrix;
};
SubdividedMesh subdivide(const ControlMesh& mesh);

}  // namespace dynsub
