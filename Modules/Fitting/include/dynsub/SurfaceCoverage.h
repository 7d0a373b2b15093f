#pragma once
// How much of a fitted surface the scan covers. The fit's error goes from
// the points to the surface, so surface where the scan has no points is
// never measured by it: a model of lower genus than the scan spans its holes
// with membranes, a closed model caps an open scan's openings, and a model
// that has not followed a limb or a fold stretches a web across the gap, and
// each such fit can meet its tolerance. This measures the other direction,
// from each vertex of the output tessellation (ModelOutputs.h) to the
// nearest point of the scan.
//
// A vertex is uncovered when that distance exceeds kCoverageSpacings times
// the points' spacing plus the fit's max error (the surface's own offset
// from the points, which a covered vertex may have too). On the synthetic
// tuning clouds (Tools/tuning_clouds.py) and the torus fitted from the torus,
// 3 spacings left at most 0.1 % of the area uncovered and 4 none; on clouds
// sampled from CGAL's meshes (Tools/sample_mesh.py), the cap over a
// mushroom's opening left 4 %, a sphere over the torus's hole 10 % and the
// webs between a cow's or a camel's legs 13 and 28 %.
#include <vector>

#include "dynsub/Tessellation.h"
#include "dynsub/Types.h"

namespace dynsub {

constexpr double kCoverageSpacings = 4.0;

struct SurfaceCoverage {
  double spacing = 0.0;            // mm: the median over the points of the distance to their nearest point elsewhere
  double maxGap = 0.0;             // mm: the largest distance from a tessellation vertex to its nearest point
  double limit = 0.0;              // mm: kCoverageSpacings x spacing + the max error, beyond which it is uncovered
  double uncoveredFraction = 0.0;  // of the surface's area (above)
  Eigen::VectorXd distances;       // mm: from each tessellation vertex to its nearest point
};

// `points`: what the surface was fitted to (outliers set aside), at least 2;
// `maxError`: the fit's largest distance from a point to the surface, mm.
SurfaceCoverage measureSurfaceCoverage(const TriangleSurface& surface, const MatrixX3& points, double maxError);

// About `count` points spread evenly over a mesh's polygons (each cut into a
// fan of triangles), and at least one per triangle: the centroids of a
// regular subdivision of each triangle. A mesh's vertices are no sample of
// its surface (a large flat triangle has none inside), so a mesh's coverage
// is measured against these. Faces naming a vertex out of range are left
// out; empty when the faces have no area.
MatrixX3 sampleMeshFaces(const MatrixX3& points, const std::vector<std::vector<int>>& faces, int count);

}  // namespace dynsub
