#include "dynsub/ScanNoise.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <tuple>
#include <vector>

#include <Eigen/Eigenvalues>

#include "dynsub/Error.h"
#include "dynsub/ParallelFor.h"
#include "dynsub/Percentile.h"
#include "PointTree.h"

namespace dynsub {

namespace {

// 1 / Phi^-1(3/4): turns a median absolute deviation into a Gaussian's sigma.
constexpr double kMadToSigma = 1.4826;

// The noise is read from this quantile of |t| over the points, and
// Phi^-1((1 + q) / 2) turns it into a Gaussian's sigma (see ScanNoise.h).
constexpr double kNoiseQuantile = 0.25;
constexpr double kQuantileToSigma = 0.318639;

double medianAbs(const Eigen::VectorXd& values) {
  std::vector<double> a(static_cast<size_t>(values.size()));
  for (Eigen::Index i = 0; i < values.size(); ++i) a[static_cast<size_t>(i)] = std::abs(values(i));
  return percentile(std::move(a), 0.5);
}

// The monomials of z = q(x, y).
Eigen::Matrix<double, 1, 6> quadricTerms(double x, double y) {
  Eigen::Matrix<double, 1, 6> row;
  row << 1.0, x, y, x * x, x * y, y * y;
  return row;
}

// A quadric fitted to some of a point's neighbours, and what it predicts at the point.
struct LocalFit {
  Eigen::VectorXd residuals;  // of the neighbours used, along the frame's z
  double scale = 0.0;         // 1.4826 median |residual|
  double standardized = 0.0;  // the point's offset / sqrt(1 + leverage)
  bool valid = false;
};

LocalFit fitQuadric(const MatrixX3& neighbours, const Vector3& point) {
  LocalFit fit;
  const Eigen::RowVector3d centroid = neighbours.colwise().mean();
  const MatrixX3 centred = neighbours.rowwise() - centroid;
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> pca(centred.transpose() * centred);
  const Eigen::Matrix3d axes = pca.eigenvectors();  // columns, by increasing eigenvalue: z, then the plane's two
  const Eigen::MatrixX3d local = centred * axes;      // columns: z, y, x
  const double extent = std::sqrt(std::max(pca.eigenvalues()(2), 1e-300) / static_cast<double>(neighbours.rows()));
  // Coordinates in units of the neighbourhood's extent keep the normal
  // equations well scaled.
  Eigen::MatrixXd terms(neighbours.rows(), 6);
  for (Eigen::Index j = 0; j < neighbours.rows(); ++j) {
    terms.row(j) = quadricTerms(local(j, 2) / extent, local(j, 1) / extent);
  }
  const Eigen::Matrix<double, 6, 6> normal = terms.transpose() * terms;
  const Eigen::LDLT<Eigen::Matrix<double, 6, 6>> solver(normal);
  if (solver.info() != Eigen::Success || !solver.isPositive() ||
      solver.vectorD().minCoeff() <= 1e-12 * solver.vectorD().maxCoeff()) {
    return fit;  // the neighbours are on a line or a point: no surface to compare with
  }
  const Eigen::Matrix<double, 6, 1> coefficients = solver.solve(terms.transpose() * local.col(0));
  fit.residuals = local.col(0) - terms * coefficients;
  fit.scale = kMadToSigma * medianAbs(fit.residuals);
  const Eigen::RowVector3d p = (point.transpose() - centroid) * axes;
  const Eigen::Matrix<double, 1, 6> at = quadricTerms(p(2) / extent, p(1) / extent);
  const double leverage = at * solver.solve(at.transpose());
  fit.standardized = (p(0) - at * coefficients) / std::sqrt(1.0 + leverage);
  fit.valid = std::isfinite(fit.standardized);
  return fit;
}

// fitQuadric, then again without the neighbours the first fit left farther
// than 3 of its scales, so that an outlier among them neither tilts the frame
// nor bends the quadric.
LocalFit fitRobustQuadric(const MatrixX3& around, const Vector3& point) {
  const LocalFit fit = fitQuadric(around, point);
  if (!fit.valid) return fit;
  std::vector<Eigen::Index> kept;
  for (Eigen::Index j = 0; j < around.rows(); ++j) {
    if (std::abs(fit.residuals(j)) <= 3.0 * fit.scale) kept.push_back(j);
  }
  if (kept.size() == static_cast<size_t>(around.rows()) || kept.size() < 10) return fit;
  const LocalFit refit = fitQuadric(around(kept, Eigen::all), point);
  return refit.valid ? refit : fit;
}

// The robust sigma of the valid standardized residuals (ScanNoise.h); 0 when none is.
double scatterOf(const Eigen::VectorXd& standardized, const std::vector<char>& valid) {
  std::vector<double> magnitudes;
  for (Eigen::Index i = 0; i < standardized.size(); ++i) {
    if (valid[static_cast<size_t>(i)]) magnitudes.push_back(std::abs(standardized(i)));
  }
  return magnitudes.empty() ? 0.0 : percentile(std::move(magnitudes), kNoiseQuantile) / kQuantileToSigma;
}

}  // namespace

Eigen::MatrixXi nearestNeighbours(const MatrixX3& points, int count) {
  if (count < 1 || count >= points.rows()) {
    throw Error("asked for " + std::to_string(count) + " neighbours of each of " + std::to_string(points.rows()) +
                " points");
  }
  const PointRows rows{points};
  const PointTree tree(3, rows, nanoflann::KDTreeSingleIndexAdaptorParams(16));  // built here
  Eigen::MatrixXi neighbours(points.rows(), count);
  parallelFor(points.rows(), threadsWorth(points.rows()), [&](Eigen::Index i) {
    // The point itself is among the count + 1 answers (at distance 0, tied
    // with any duplicate of it): ask for one more, and drop it.
    std::vector<unsigned> found(static_cast<size_t>(count) + 1);  // nanoflann's index type
    std::vector<double> squared(static_cast<size_t>(count) + 1);
    const Vector3 q = points.row(i).transpose();
    const size_t got = tree.knnSearch(q.data(), found.size(), found.data(), squared.data());
    int column = 0;
    for (size_t f = 0; f < got && column < count; ++f) {
      if (static_cast<Eigen::Index>(found[f]) != i) neighbours(i, column++) = static_cast<int>(found[f]);
    }
  });
  return neighbours;
}

MatrixX3 withoutRows(const MatrixX3& points, const std::vector<int>& drop) {
  MatrixX3 kept(points.rows() - static_cast<Eigen::Index>(drop.size()), 3);
  Eigen::Index next = 0;
  size_t d = 0;
  for (Eigen::Index i = 0; i < points.rows(); ++i) {
    if (d < drop.size() && drop[d] == i) {
      ++d;
      continue;
    }
    kept.row(next++) = points.row(i);
  }
  return kept;
}

namespace {

// estimateScanNoise on points that are all distinct.
ScanNoise estimateOnDistinct(const MatrixX3& points) {
  const Eigen::MatrixXi neighbours = nearestNeighbours(points, kNoiseNeighbours);
  const Eigen::Index n = points.rows();
  Eigen::VectorXd standardized = Eigen::VectorXd::Zero(n), localScale = Eigen::VectorXd::Zero(n);
  Eigen::VectorXd reach(n), nearest(n);  // mean and least distance to the neighbours
  Eigen::VectorXd fewStandardized = Eigen::VectorXd::Zero(n);
  std::vector<char> valid(static_cast<size_t>(n), 0), fewValid(static_cast<size_t>(n), 0);
  parallelFor(n, threadsWorth(n), [&](Eigen::Index i) {
    MatrixX3 around(kNoiseNeighbours, 3);
    for (int j = 0; j < kNoiseNeighbours; ++j) around.row(j) = points.row(neighbours(i, j));
    const Vector3 point = points.row(i).transpose();
    const Eigen::VectorXd distances = (around.rowwise() - point.transpose()).rowwise().norm();
    reach(i) = distances.mean();
    nearest(i) = distances(0);
    const LocalFit fit = fitRobustQuadric(around, point);
    if (fit.valid) {
      standardized(i) = fit.standardized;
      localScale(i) = fit.scale;
      valid[static_cast<size_t>(i)] = 1;
    }
    const LocalFit few = fitRobustQuadric(around.topRows(kNoiseNeighboursFew), point);  // the nearest first
    if (few.valid) {
      fewStandardized(i) = few.standardized;
      fewValid[static_cast<size_t>(i)] = 1;
    }
  });
  ScanNoise noise;
  noise.scatter = scatterOf(standardized, valid);
  noise.scatterFew = scatterOf(fewStandardized, fewValid);
  noise.sigma = noise.scatter > kShapeGrowth * noise.scatterFew ? 0.0 : noise.scatter;
  const double spacing = percentile(std::vector<double>(nearest.data(), nearest.data() + n), 0.5);
  const double usualReach = percentile(std::vector<double>(reach.data(), reach.data() + n), 0.5);
  for (Eigen::Index i = 0; i < n; ++i) {
    // Isolated: the neighbours are much farther from the point than its
    // neighbours' own are from theirs (the median of their reaches), or than
    // points' neighbours usually are: outliers off a large empty interior
    // have other outliers for neighbours. A point far off the surface has no
    // patch of it as neighbours, only scattered points, which no quadric
    // describes, so the offset test below cannot judge it.
    std::vector<double> around(kNoiseNeighbours);
    for (int j = 0; j < kNoiseNeighbours; ++j) around[static_cast<size_t>(j)] = reach(neighbours(i, j));
    const bool isolated = reach(i) > kIsolationFactor * std::min(usualReach, percentile(std::move(around), 0.5));
    // Off the neighbours' surface by many scales, and by more than half the
    // usual spacing of the points: on clean data the scales are the quadrics'
    // tiny misfit, and an offset within the spacing cannot pull a fit anywhere.
    const bool off = valid[static_cast<size_t>(i)] &&
                     std::abs(standardized(i)) > kOutlierFactor * std::max(noise.scatter, localScale(i)) &&
                     std::abs(standardized(i)) > 0.5 * spacing;
    if (isolated || off) noise.outliers.push_back(static_cast<int>(i));
  }
  return noise;
}

}  // namespace

ScanNoise estimateScanNoise(const MatrixX3& points) {
  if (points.rows() <= kNoiseNeighbours) {
    throw Error("the noise of a scan is measured on at least " + std::to_string(kNoiseNeighbours + 1) +
                " points; it has " + std::to_string(points.rows()));
  }
  // Copies of one point (a file written twice, overlapping scans merged)
  // would be one another's nearest neighbours: every local quadric would fit
  // them exactly, the scatter would come out near 0, and clean points would
  // be set aside as outliers. Each position counts once.
  const Eigen::Index n = points.rows();
  std::vector<Eigen::Index> order(static_cast<size_t>(n));
  for (Eigen::Index i = 0; i < n; ++i) order[static_cast<size_t>(i)] = i;
  const auto less = [&points](Eigen::Index a, Eigen::Index b) {
    return std::tie(points(a, 0), points(a, 1), points(a, 2)) < std::tie(points(b, 0), points(b, 1), points(b, 2));
  };
  std::sort(order.begin(), order.end(), less);
  std::vector<int> distinctOf(static_cast<size_t>(n));
  std::vector<Eigen::Index> firsts;
  for (size_t k = 0; k < order.size(); ++k) {
    if (k == 0 || points.row(order[k]) != points.row(order[k - 1])) firsts.push_back(order[k]);
    distinctOf[static_cast<size_t>(order[k])] = static_cast<int>(firsts.size()) - 1;
  }
  if (static_cast<Eigen::Index>(firsts.size()) == n) return estimateOnDistinct(points);
  // Too few distinct points to measure: no noise, and none set aside.
  if (static_cast<Eigen::Index>(firsts.size()) <= kNoiseNeighbours) return ScanNoise{};
  ScanNoise noise = estimateOnDistinct(points(firsts, Eigen::all));
  std::vector<char> outlier(firsts.size(), 0);
  for (const int d : noise.outliers) outlier[static_cast<size_t>(d)] = 1;
  noise.outliers.clear();
  for (Eigen::Index i = 0; i < n; ++i)
    if (outlier[static_cast<size_t>(distinctOf[static_cast<size_t>(i)])]) noise.outliers.push_back(static_cast<int>(i));
  return noise;
}

}  // namespace dynsub
