#pragma once
// Polygons' areas, as the checks of control meshes (MeshCheck.h) and of
// lattices (Lattice.h) judge a face of no area.
#include <cmath>
#include <sstream>
#include <string>
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

// Why the polygon `loop` counts as having no area, or empty when it has one:
// none beside its own size (its points on a line), or none beside the
// whole's (at most `minimumArea`, degenerateArea), as every ordinary polygon
// becomes when one point lies far from the rest.
inline std::string noAreaReason(const MatrixX3& points, const std::vector<int>& loop, double minimumArea) {
  const double area = 0.5 * newellNormal(points, loop).norm();
  if (area > minimumArea) return "";
  Vector3 low = points.row(loop[0]).transpose(), high = low;
  for (int p : loop) {
    low = low.cwiseMin(points.row(p).transpose());
    high = high.cwiseMax(points.row(p).transpose());
  }
  const double ownDiagonal = (high - low).norm();
  if (!(area > 1e-12 * ownDiagonal * ownDiagonal)) return "its area is zero";
  std::ostringstream why;
  why << "its area, " << area << ", is below 1e-12 of the square of the whole's extent, "
      << std::sqrt(minimumArea * 1e12) << ": is a point far from the others (a mistyped coordinate)?";
  return why.str();
}

}  // namespace dynsub
