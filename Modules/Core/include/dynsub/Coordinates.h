#pragma once
// The coordinates DynSub's readers accept, and their words for one beyond.
#include <string>

#include "dynsub/Types.h"

namespace dynsub {

// The largest coordinate (mm) the readers accept, of a point or a mesh
// vertex: a kilometre-scale survey fits, and the squares and products of
// coordinates that distances and areas take stay far from overflow.
constexpr double kLargestCoordinate = 1e9;

// "(x, y, z) lies beyond 1e+09 mm of the origin; coordinates are in mm" when
// a coordinate of `point` exceeds kLargestCoordinate, else empty: the end of
// a reader's error that names the point.
std::string beyondLargestCoordinate(const Vector3& point);

}  // namespace dynsub
