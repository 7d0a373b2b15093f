#pragma once
// Where a tessellated surface passes through itself. A fitted surface can: a
// landmark or an edge may pull one part of it through another, and then
// surface.vtp is no longer the boundary of a solid: tools that need one, such
// as a mesh boolean, a thickness measure or a mask filled by the even-odd
// rule, refuse it or go wrong there. DynSub's own labelmap is filled by the
// nonzero rule (Voxelize.h), which counts what two sheets enclose as inside.
//
// Two triangles cross when an edge of one passes through the other. Pairs
// that share a sample are not tested: neighbours meet along their common edge
// or corner by construction, so a fold narrower than one triangle around a
// sample is not seen. Samples that coincide (a sharp crease's two sides,
// written once per side: Tessellation.h) count as shared.
#include <vector>

#include "dynsub/Tessellation.h"

namespace dynsub {

struct SelfIntersection {
  int trianglePairs = 0;       // pairs of triangles that cross
  std::vector<int> triangles;  // the triangles in those pairs, ascending
  double areaPercent = 0.0;    // their share of the surface's area
  // Their bounding box (mm); zero when there are none.
  Vector3 boundsMin = Vector3::Zero(), boundsMax = Vector3::Zero();
};

SelfIntersection findSelfIntersections(const TriangleSurface& surface);

}  // namespace dynsub
