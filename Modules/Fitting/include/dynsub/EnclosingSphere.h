#pragma once
// The smallest sphere enclosing a point set: the reference length of the
// papers' fit error (TVCG §4.2: error as a percentage of the diameter of the
// smallest sphere enclosing the object).
//
// Welzl's randomized algorithm (1991) in the move-to-front-free recursive form
// on at most 4 support points, over the points in a shuffled order with a
// fixed seed (deterministic). Expected O(n). Points count as inside with a
// relative tolerance of 1e-10 of the radius.
#include "dynsub/Types.h"

namespace dynsub {

struct Sphere {
  Vector3 center = Vector3::Zero();
  double radius = 0;
};

// Throws dynsub::Error for an empty or non-finite point set.
Sphere smallestEnclosingSphere(const MatrixX3& points);

}  // namespace dynsub
