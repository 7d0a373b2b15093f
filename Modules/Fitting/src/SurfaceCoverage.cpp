#include "dynsub/SurfaceCoverage.h"

#include <algorithm>
#include <cmath>

#include "dynsub/Error.h"
#include "dynsub/ParallelFor.h"
#include "dynsub/Percentile.h"
#include "PointTree.h"

namespace dynsub {

SurfaceCoverage measureSurfaceCoverage(const TriangleSurface& surface, const MatrixX3& points, double maxError) {
  if (points.rows() < 2) throw Error("internal: the coverage of a surface needs at least 2 points");
  const PointRows rows{points};
  const PointTree tree(3, rows, nanoflann::KDTreeSingleIndexAdaptorParams(16));
  SurfaceCoverage coverage;

  // The nearest other point at a distance: a scan may repeat points (an
  // export that did not merge them), and their zeros are no spacing.
  std::vector<double> nearest(static_cast<size_t>(points.rows()), 0.0);
  parallelFor(points.rows(), threadsWorth(points.rows()), [&](Eigen::Index i) {
    constexpr size_t kAsked = 8;
    unsigned found[kAsked];
    double squared[kAsked];
    const Vector3 q = points.row(i).transpose();
    const size_t got = tree.knnSearch(q.data(), std::min<size_t>(kAsked, points.rows()), found, squared);
    for (size_t k = 0; k < got; ++k) {
      if (squared[k] > 0.0) {
        nearest[static_cast<size_t>(i)] = std::sqrt(squared[k]);
        break;
      }
    }
  });
  nearest.erase(std::remove(nearest.begin(), nearest.end(), 0.0), nearest.end());
  coverage.spacing = nearest.empty() ? 0.0 : percentile(std::move(nearest), 0.5);

  const Eigen::Index n = surface.points.rows();
  Eigen::VectorXd& gap = coverage.distances;
  gap.resize(n);
  parallelFor(n, threadsWorth(n), [&](Eigen::Index v) {
    unsigned found = 0;
    double squared = 0.0;
    const Vector3 q = surface.points.row(v).transpose();
    tree.knnSearch(q.data(), 1, &found, &squared);
    gap(v) = std::sqrt(squared);
  });
  coverage.maxGap = n > 0 ? gap.maxCoeff() : 0.0;

  // Each vertex stands for a third of the area of the triangles around it.
  Eigen::VectorXd area = Eigen::VectorXd::Zero(n);
  for (const auto& t : surface.triangles) {
    const Vector3 a = surface.points.row(t[0]).transpose();
    const Vector3 b = surface.points.row(t[1]).transpose();
    const Vector3 c = surface.points.row(t[2]).transpose();
    const double third = (b - a).cross(c - a).norm() / 6.0;
    for (int corner : t) area(corner) += third;
  }
  const double total = area.sum();
  coverage.limit = kCoverageSpacings * coverage.spacing + maxError;
  double uncovered = 0.0;
  for (Eigen::Index v = 0; v < n; ++v)
    if (gap(v) > coverage.limit) uncovered += area(v);
  coverage.uncoveredFraction = total > 0.0 ? uncovered / total : 0.0;
  return coverage;
}

MatrixX3 sampleMeshFaces(const MatrixX3& points, const std::vector<std::vector<int>>& faces, int count) {
  struct Triangle {
    Vector3 a, b, c;
    double area, longest;
  };
  std::vector<Triangle> triangles;
  double total = 0.0;
  for (const auto& face : faces) {
    const bool inRange = std::all_of(face.begin(), face.end(), [&](int v) { return v >= 0 && v < points.rows(); });
    if (!inRange) continue;
    for (size_t k = 1; k + 1 < face.size(); ++k) {
      Triangle t{points.row(face[0]).transpose(), points.row(face[k]).transpose(), points.row(face[k + 1]).transpose(),
                 0.0, 0.0};
      t.area = 0.5 * (t.b - t.a).cross(t.c - t.a).norm();
      total += t.area;
      triangles.push_back(t);
    }
  }
  if (count < 1) throw Error("internal: asked for no samples of a mesh");
  if (!(total > 0.0)) return MatrixX3();
  // A triangle cut into m x m sub-triangles about h apart along its longest
  // edge L gives m^2 = (L / h)^2 samples: h is set so that they add up to
  // `count`.
  double squares = 0.0;
  for (Triangle& t : triangles) {
    t.longest = std::max({(t.b - t.a).norm(), (t.c - t.b).norm(), (t.a - t.c).norm()});
    squares += t.longest * t.longest;
  }
  const double h = std::sqrt(squares / count);
  std::vector<Vector3> samples;
  for (const Triangle& t : triangles) {
    // But not more than about 4 times the triangle's share of `count` by
    // area: a sliver's interior is no wider than its samples.
    const double most = 2.0 * std::sqrt(count * t.area / total) + 1.0;
    const int m = std::max(1, static_cast<int>(std::ceil(std::min(t.longest / h, most))));
    const Vector3 u = (t.b - t.a) / m, v = (t.c - t.a) / m;
    for (int i = 0; i < m; ++i) {
      for (int j = 0; i + j < m; ++j) {
        samples.push_back(t.a + (i + 1.0 / 3.0) * u + (j + 1.0 / 3.0) * v);
        if (i + j + 1 < m) samples.push_back(t.a + (i + 2.0 / 3.0) * u + (j + 2.0 / 3.0) * v);
      }
    }
  }
  MatrixX3 result(static_cast<Eigen::Index>(samples.size()), 3);
  for (size_t s = 0; s < samples.size(); ++s) result.row(static_cast<Eigen::Index>(s)) = samples[s].transpose();
  return result;
}

}  // namespace dynsub
