#pragma once
// Image grids for tests: oblique ones, where the index axes and LPS differ.
#include <array>

#include <Eigen/Geometry>

#include "dynsub/Volume.h"

namespace dynsub {

// A rotation about a skew axis: no axis of the grid is aligned with LPS.
inline Matrix3 skewDirection() {
  return Eigen::AngleAxisd(0.5, Vector3(1, 2, 3).normalized()).toRotationMatrix();
}

inline ImageGeometry grid(std::array<int, 3> size, Vector3 spacing, Vector3 origin, Matrix3 direction) {
  ImageGeometry g;
  g.size = size;
  g.spacing = spacing;
  g.origin = origin;
  g.direction = direction;
  return g;
}

}  // namespace dynsub
