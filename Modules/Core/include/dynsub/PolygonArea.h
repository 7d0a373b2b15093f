#pragma once
// Polygons' areas, as the checks of control meshes (MeshCheck.h) and of
// lattices (Lattice.h) judge a face of no area.
#include <vector>

#include "dynsub/Types.h"

namespace dynsub {

// Newell's normal of the polygon through the rows `loop` of `points`: its
// length is twice the area of a planar polygon, and robust for others; it
// points the way the loop runs counter-clockwise around.
inline Vector3 newellNormal(const MatrixX3& points, const std::vector<int>& loop) {
  Vector3 normal = Vector3::Zero();
  for (std::size_t i = 0; i < loop.size(); ++i)
    normal += Vector3(points.row(loop[i]).transpose()).cross(points.row(loop[(i + 1) % loop.size()]).transpose());
  return normal;
}

// The area up to which a polygon among `points` counts as having none: 1e-12
// of the squared diagonal of their bounding box, relative so that a mesh in
// micrometres or in metres is judged alike.
inline double degenerateArea(const MatrixX3& points) {
  const double diagonal = (points.colwise().maxCoeff() - points.colwise().minCoeff()).norm();
  return 1e-12 * diagonal * diagonal;
}

}  // namespace dynsub
