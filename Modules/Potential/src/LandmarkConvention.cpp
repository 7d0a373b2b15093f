#include "dynsub/LandmarkConvention.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include <Eigen/Cholesky>

#include "dynsub/EdgePotential.h"
#include "dynsub/Error.h"
#include "dynsub/ImageFilters.h"
#include "dynsub/Percentile.h"

namespace dynsub {
namespace {

// The edges at one reading of the points. Each point's strongest edge is
// looked for within `reach` of it, so the smoothed gradient is computed on
// that small box alone (smoothedGradientIn): a few dozen voxels a point,
// where the points' whole box holds tens of thousands for each reading.
ReadingEdges edgesAt(const Volume& image, const MatrixX3& points, double sigma, double reach) {
  for (Eigen::Index p = 0; p < points.rows(); ++p)
    if (!image.geometry.covers(points.row(p).transpose())) return {};
  // The outward normal of the points' PCA ellipsoid at each point, C^-1 (p - c):
  // where a boundary click's edge should face.
  const Eigen::RowVector3d centre = points.colwise().mean();
  const MatrixX3 centred = points.rowwise() - centre;
  const Matrix3 covariance = centred.transpose() * centred / static_cast<double>(points.rows()) +
                             1e-6 * Matrix3::Identity();
  const Eigen::LDLT<Matrix3> inverse(covariance);
  // A voxel more than the reach: the box holds every voxel
  // strongestVoxelNear weighs, half a voxel beyond the reach on thick axes.
  const double margin = reach + image.geometry.spacing.maxCoeff();
  std::vector<double> strengths;
  double alignment = 0;
  for (Eigen::Index p = 0; p < points.rows(); ++p) {
    const Vector3 point = points.row(p).transpose();
    const auto [first, size] = boundingRegion(image.geometry, points.row(p), margin);
    const std::vector<Vector3> gradient = smoothedGradientIn(image, sigma, first, size);
    const Volume magnitude = magnitudeOf(image.geometry.region(first, size), gradient);
    const StrongestVoxel strongest = strongestVoxelNear(magnitude, point, reach);
    strengths.push_back(strongest.magnitude);
    const Vector3 normal = inverse.solve(Vector3(centred.row(p).transpose()));
    if (strongest.offset >= 0 && strongest.magnitude > 0 && normal.norm() > 0)
      alignment += std::abs(gradient[strongest.offset].dot(normal)) / (strongest.magnitude * normal.norm());
  }
  return {percentile(strengths, 0.5), alignment / static_cast<double>(points.rows())};
}

}  // namespace

MatrixX3 misread(const MatrixX3& points, Misreading misreading) {
  MatrixX3 read = points;
  if (misreading != Misreading::None) read.col(0) *= -1;
  if (misreading == Misreading::Flipped) read.col(1) *= -1;
  return read;
}

ConventionScores conventionScores(const Volume& image, const MatrixX3& points, double sigma, double reach) {
  if (points.rows() < 4) throw Error("the convention check needs at least 4 points");
  if (!(sigma > 0) || !std::isfinite(sigma) || !(reach > 0) || !std::isfinite(reach))
    throw Error("the convention check's smoothing and reach must be positive and finite");
  ConventionScores scores;
  scores.asRead = edgesAt(image, points, sigma, reach);
  scores.flipped = edgesAt(image, misread(points, Misreading::Flipped), sigma, reach);
  scores.mirrored = edgesAt(image, misread(points, Misreading::Mirrored), sigma, reach);
  return scores;
}

double misreadingEvidence(const ConventionScores& scores, Misreading misreading) {
  if (misreading == Misreading::None) return 0;
  const ReadingEdges& other = misreading == Misreading::Flipped ? scores.flipped : scores.mirrored;
  if (!(other.strength > 0)) return 0;  // a point outside the image
  const double floor =
      0.01 * std::max({scores.asRead.strength, scores.flipped.strength, scores.mirrored.strength});
  return std::log((other.strength + floor) / (scores.asRead.strength + floor)) +
         kAlignmentWeight * (other.alignment - scores.asRead.alignment);
}

Misreading likelyMisreading(const ConventionScores& scores) {
  const double flipped = misreadingEvidence(scores, Misreading::Flipped);
  const double mirrored = misreadingEvidence(scores, Misreading::Mirrored);
  if (std::max(flipped, mirrored) < kMisreadingEvidence) return Misreading::None;
  return flipped >= mirrored ? Misreading::Flipped : Misreading::Mirrored;
}

}  // namespace dynsub
