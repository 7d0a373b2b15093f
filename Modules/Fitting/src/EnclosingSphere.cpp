#include "dynsub/EnclosingSphere.h"

#include <algorithm>
#include <numeric>
#include <random>
#include <vector>

#include <Eigen/LU>

#include "dynsub/Error.h"

namespace dynsub {

namespace {

constexpr double kSlack = 1e-10;

bool contains(const Sphere& s, const Vector3& p) { return (p - s.center).norm() <= s.radius * (1.0 + kSlack) + 1e-300; }

Sphere through(const Vector3& a) { return Sphere{a, 0.0}; }
Sphere through(const Vector3& a, const Vector3& b) { return Sphere{0.5 * (a + b), 0.5 * (a - b).norm()}; }

// The circumcircle of a triangle, as a sphere; falls back to the widest pair
// for (nearly) collinear points.
Sphere through(const Vector3& a, const Vector3& b, const Vector3& c) {
  const Vector3 ab = b - a, ac = c - a;
  const Vector3 normal = ab.cross(ac);
  const double denominator = 2.0 * normal.squaredNorm();
  if (denominator <= 1e-24 * ab.squaredNorm() * ac.squaredNorm()) {
    Sphere best = through(a, b);
    for (const Sphere& s : {through(a, c), through(b, c)}) {
      if (s.radius > best.radius) best = s;
    }
    return best;
  }
  const Vector3 offset = (ac.squaredNorm() * normal.cross(ab) + ab.squaredNorm() * ac.cross(normal)) / denominator;
  return Sphere{a + offset, offset.norm()};
}

// The circumsphere of a tetrahedron; for (nearly) coplanar points, the
// smallest of the triangle circles that holds all four.
Sphere through(const Vector3& a, const Vector3& b, const Vector3& c, const Vector3& d) {
  Eigen::Matrix3d m;
  m.row(0) = (b - a).transpose();
  m.row(1) = (c - a).transpose();
  m.row(2) = (d - a).transpose();
  const Vector3 rhs(0.5 * (b - a).squaredNorm(), 0.5 * (c - a).squaredNorm(), 0.5 * (d - a).squaredNorm());
  const Eigen::FullPivLU<Eigen::Matrix3d> lu(m);
  if (lu.rank() == 3) {
    const Vector3 offset = lu.solve(rhs);
    return Sphere{a + offset, offset.norm()};
  }
  Sphere best{Vector3::Zero(), std::numeric_limits<double>::infinity()};
  const Vector3 points[4] = {a, b, c, d};
  for (int skip = 0; skip < 4; ++skip) {
    Vector3 t[3];
    for (int i = 0, k = 0; i < 4; ++i) {
      if (i != skip) t[k++] = points[i];
    }
    const Sphere s = through(t[0], t[1], t[2]);
    if (contains(s, points[skip]) && s.radius < best.radius) best = s;
  }
  return best;
}

struct Welzl {
  const MatrixX3& points;
  const std::vector<int>& order;
  Vector3 at(int i) const { return points.row(order[i]).transpose(); }

  // The smallest sphere of points [0, end) with the given support points on its boundary.
  Sphere solve(int end, std::vector<Vector3>& support) const {
    Sphere s;
    switch (support.size()) {
      case 0: s = Sphere{at(0), 0.0}; break;
      case 1: s = through(support[0]); break;
      case 2: s = through(support[0], support[1]); break;
      case 3: s = through(support[0], support[1], support[2]); break;
      default: return through(support[0], support[1], support[2], support[3]);
    }
    for (int i = support.empty() ? 1 : 0; i < end; ++i) {
      const Vector3 p = at(i);
      if (contains(s, p)) continue;
      support.push_back(p);
      s = solve(i, support);
      support.pop_back();
    }
    return s;
  }
};

}  // namespace

Sphere smallestEnclosingSphere(const MatrixX3& points) {
  if (points.rows() == 0) throw Error("cannot enclose an empty point set");
  if (!points.allFinite()) throw Error("cannot enclose points with non-finite coordinates");
  std::vector<int> order(points.rows());
  std::iota(order.begin(), order.end(), 0);
  // A fixed permutation (our own Fisher-Yates on a fixed-seed generator, so the
  // order does not depend on the standard library's shuffle).
  std::mt19937_64 random(20261122);
  for (int i = static_cast<int>(order.size()) - 1; i > 0; --i) {
    std::swap(order[i], order[static_cast<int>(random() % static_cast<uint64_t>(i + 1))]);
  }
  std::vector<Vector3> support;
  return Welzl{points, order}.solve(static_cast<int>(order.size()), support);
}

}  // namespace dynsub
