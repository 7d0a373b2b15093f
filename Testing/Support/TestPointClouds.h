#pragma once
// Seeded point clouds on analytic shapes, for tests of fitting and dynamics.
#include <cmath>
#include <random>

#include "dynsub/Types.h"

namespace dynsub {

inline Vector3 randomDirection(std::mt19937_64& random) {
  std::normal_distribution<double> normal;
  Vector3 v;
  do {
    v = Vector3(normal(random), normal(random), normal(random));
  } while (v.norm() < 1e-6);
  return v.normalized();
}

// n points on the ellipsoid of semi-axes `axes` around the origin.
inline MatrixX3 ellipsoidPoints(int n, const Vector3& axes, unsigned seed) {
  std::mt19937_64 random(seed);
  MatrixX3 points(n, 3);
  for (int i = 0; i < n; ++i) points.row(i) = randomDirection(random).cwiseProduct(axes).transpose();
  return points;
}

// n points on the torus of ring radius `ring` and tube radius `tube` around the z axis.
inline MatrixX3 torusPoints(int n, double ring, double tube, unsigned seed) {
  std::mt19937_64 random(seed);
  std::uniform_real_distribution<double> angle(0.0, 2.0 * M_PI);
  MatrixX3 points(n, 3);
  for (int i = 0; i < n; ++i) {
    const double theta = angle(random), phi = angle(random);
    const double r = ring + tube * std::cos(phi);
    points.row(i) << r * std::cos(theta), r * std::sin(theta), tube * std::sin(phi);
  }
  return points;
}

// n points uniform over the faces of the cube [-half, half]^3.
inline MatrixX3 boxPoints(int n, double half, unsigned seed) {
  std::mt19937_64 random(seed);
  std::uniform_int_distribution<int> face(0, 5);
  std::uniform_real_distribution<double> across(-half, half);
  MatrixX3 points(n, 3);
  for (int i = 0; i < n; ++i) {
    const int f = face(random), axis = f / 2;
    points(i, axis) = f % 2 == 0 ? -half : half;
    points(i, (axis + 1) % 3) = across(random);
    points(i, (axis + 2) % 3) = across(random);
  }
  return points;
}

}  // namespace dynsub
