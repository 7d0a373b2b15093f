#include "dynsub/EdgePotential.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <vector>

#include "dynsub/Error.h"
#include "dynsub/ImageFilters.h"
#include "dynsub/ParallelFor.h"
#include "dynsub/Percentile.h"

namespace dynsub {
namespace {

// body(k) for every slice k of the grid, on two threads when the grid is
// large enough to pay for the second (a segmentation's region of 36 x 62 x 57
// voxels is). Each voxel's result must depend on the input alone, so the
// split changes nothing.
template <class Body>
void forEachSlice(const ImageGeometry& g, const Body& body) {
  parallelFor(g.size[2], g.voxelCount() >= (1 << 15) ? 2 : 1, body);
}


}  // namespace

Volume magnitudeOf(const ImageGeometry& geometry, const std::vector<Vector3>& gradient) {
  Volume magnitude{geometry, std::vector<float>(gradient.size())};
  const long long slice = static_cast<long long>(geometry.size[0]) * geometry.size[1];
  forEachSlice(geometry, [&](Eigen::Index k) {
    for (long long v = k * slice; v < (k + 1) * slice; ++v) magnitude.voxels[v] = static_cast<float>(gradient[v].norm());
  });
  return magnitude;
}

StrongestVoxel strongestVoxelNear(const Volume& magnitude, const Vector3& point, double radius) {
  const ImageGeometry& g = magnitude.geometry;
  const Vector3 centre = g.toIndex(point);
  StrongestVoxel strongest;
  int reach[3];
  Vector3 slab = Vector3::Zero();  // mm, half a voxel along thick axes
  for (int a = 0; a < 3; ++a) {
    if (0.5 * g.spacing[a] > radius) slab[a] = 0.5 * g.spacing[a];
    reach[a] = static_cast<int>(std::ceil((radius + slab[a]) / g.spacing[a]));
  }
  const bool thick = slab.maxCoeff() > 0;
  const int ci = static_cast<int>(std::lround(centre[0])), cj = static_cast<int>(std::lround(centre[1])),
            ck = static_cast<int>(std::lround(centre[2]));
  for (int k = ck - reach[2]; k <= ck + reach[2]; ++k)
    for (int j = cj - reach[1]; j <= cj + reach[1]; ++j)
      for (int i = ci - reach[0]; i <= ci + reach[0]; ++i) {
        if (!g.contains(i, j, k)) continue;
        bool near = false;
        if (thick) {  // offsets along the grid's axes (mm), less the slabs
          const Vector3 offset = (Vector3(i, j, k) - centre).cwiseProduct(g.spacing).cwiseAbs() - slab;
          near = offset.cwiseMax(0.0).norm() <= radius;
        } else {
          near = (g.toPhysical(Vector3(i, j, k)) - point).norm() <= radius;
        }
        const double m = magnitude.at(i, j, k);
        if (near && (strongest.offset < 0 || m > strongest.magnitude)) {
          strongest.magnitude = m;
          strongest.offset = g.offset(i, j, k);
        }
      }
  return strongest;
}

namespace {

// The reference magnitude and fractions of step 3 (see the header).
EdgeScale edgeScale(const Volume& magnitude, const EdgeOptions& options, const MatrixX3& landmarks) {
  const double strongEdges = percentile(magnitude.voxels, 0.99);
  if (options.reference == EdgeReference::Image || landmarks.rows() == 0)
    return {EdgeReference::Image, strongEdges, options.ofImage};
  std::vector<float> strengths;
  for (Eigen::Index p = 0; p < landmarks.rows(); ++p)
    strengths.push_back(
        static_cast<float>(strongestVoxelNear(magnitude, landmarks.row(p).transpose(), options.landmarkReach).magnitude));
  const double median = percentile(strengths, 0.5);
  // The faintest boundary segmented here (the pallidum) is at 0.11 of the
  // 99th percentile; a hundredth of it is flat tissue or off the image, and
  // thresholds set there would keep every ripple of noise as an edge (or,
  // in a region with no gradient at all, every voxel).
  if (!(strongEdges > 0))
    throw LandmarksOffEdges("the image has no edges: its intensity is constant in the segmentation's region, so the " +
                            std::to_string(landmarks.rows()) + " landmarks cannot set the edge thresholds (and "
                            "there is nothing in it to segment)");
  if (!(median > 0 && median >= 0.01 * strongEdges)) {
    std::ostringstream message;
    message << "the " << landmarks.rows() << " landmarks are not on an image edge: the median of their strongest "
            << "gradient within " << options.landmarkReach << " mm is " << median
            << ", under 1 % of the image's strong edges (99th percentile " << strongEdges
            << "), so they cannot set the edge thresholds; place them on the structure's boundary, widen the "
            << "landmarks' edge reach, or take the thresholds from the image";
    throw LandmarksOffEdges(message.str());
  }
  return {EdgeReference::Landmarks, median, options.ofLandmarks};
}

// Steps 2 and 3 of the header: non-maximum suppression along the gradient, then hysteresis.
Mask edgeMap(const Volume& magnitude, const std::vector<Vector3>& gradient, const EdgeScale& scale) {
  const ImageGeometry& g = magnitude.geometry;
  Mask edges{g, std::vector<std::uint8_t>(magnitude.voxels.size(), 0)};
  if (!(scale.magnitude > 0)) return edges;  // a constant image has no edges
  const double low = scale.fractions.low * scale.magnitude, high = scale.fractions.high * scale.magnitude;
  // A physical direction d moves the continuous index by (D^-1 d) / spacing; one
  // step is the smallest spacing long.
  const Matrix3 toIndex = g.indexFromPhysical();
  const double step = g.spacing.minCoeff();

  std::vector<std::uint8_t> candidate(magnitude.voxels.size(), 0);
  forEachSlice(g, [&](Eigen::Index slice) {
    const int k = static_cast<int>(slice);
    for (int j = 0; j < g.size[1]; ++j)
      for (int i = 0; i < g.size[0]; ++i) {
        const long long v = g.offset(i, j, k);
        const double m = magnitude.voxels[v];
        if (m < low) continue;
        const Vector3 ahead = toIndex * (gradient[v] / m * step);
        const Vector3 here(i, j, k);
        if (m >= magnitude.interpolate(here + ahead) && m >= magnitude.interpolate(here - ahead)) candidate[v] = 1;
      }
  });

  std::vector<long long> stack;
  for (long long v = 0; v < static_cast<long long>(candidate.size()); ++v)
    if (candidate[v] && magnitude.voxels[v] >= high) {
      edges.voxels[v] = 1;
      stack.push_back(v);
    }
  while (!stack.empty()) {
    const long long v = stack.back();
    stack.pop_back();
    const auto [i, j, k] = g.voxelAt(v);
    for (int dk = -1; dk <= 1; ++dk)
      for (int dj = -1; dj <= 1; ++dj)
        for (int di = -1; di <= 1; ++di) {
          if (!g.contains(i + di, j + dj, k + dk)) continue;
          const long long n = g.offset(i + di, j + dj, k + dk);
          if (candidate[n] && !edges.voxels[n]) {
            edges.voxels[n] = 1;
            stack.push_back(n);
          }
        }
  }
  return edges;
}

// The central-difference gradient of a potential, in LPS per mm, normalized,
// as x, y, z side by side per voxel; zero where the gradient vanishes or
// `keep` is false.
std::vector<float> normalizedGradient(const Volume& potential, const std::vector<std::uint8_t>& keep) {
  const ImageGeometry& g = potential.geometry;
  // d/dx_phys = D^-T (d/dindex / spacing).
  const Matrix3 toPhysical = g.direction.inverse().transpose();
  std::vector<float> vectors(3 * potential.voxels.size(), 0.0f);
  forEachSlice(g, [&](Eigen::Index slice) {
    const int k = static_cast<int>(slice);
    for (int j = 0; j < g.size[1]; ++j)
      for (int i = 0; i < g.size[0]; ++i) {
        const long long v = g.offset(i, j, k);
        if (!keep[v]) continue;
        const int at[3] = {i, j, k};
        Vector3 derivative;
        for (int a = 0; a < 3; ++a) {
          int lo[3] = {i, j, k}, hi[3] = {i, j, k};
          lo[a] = std::max(at[a] - 1, 0);
          hi[a] = std::min(at[a] + 1, g.size[a] - 1);
          const int span = hi[a] - lo[a];
          derivative[a] = span == 0 ? 0.0
                                    : (potential.at(hi[0], hi[1], hi[2]) - potential.at(lo[0], lo[1], lo[2])) /
                                          (span * g.spacing[a]);
        }
        const Vector3 gradient = toPhysical * derivative;
        const double norm = gradient.norm();
        if (!(norm > 1e-12)) continue;
        for (int a = 0; a < 3; ++a) vectors[3 * v + a] = static_cast<float>(gradient[a] / norm);
      }
  });
  return vectors;
}

}  // namespace

void checkEdgeOptions(const EdgeOptions& options) {
  if (!(options.sigma > 0) || !std::isfinite(options.sigma))
    throw Error("edge sigma must be a positive number of mm (got " + std::to_string(options.sigma) + ")");
  auto checkHysteresis = [](const Hysteresis& h, const std::string& of) {
    if (!(h.low >= 0 && h.low <= h.high && std::isfinite(h.high)))
      throw Error("edge thresholds (fractions of " + of + ") must satisfy 0 <= low <= high (got " +
                  std::to_string(h.low) + ", " + std::to_string(h.high) + ")");
  };
  checkHysteresis(options.ofLandmarks, "the landmarks' median gradient");
  checkHysteresis(options.ofImage, "the image's 99th-percentile gradient");
  if (!(options.landmarkReach > 0) || !std::isfinite(options.landmarkReach))
    throw Error("the landmarks' edge search radius must be a positive number of mm (got " +
                std::to_string(options.landmarkReach) + ")");
  if (!(options.captureRange > 0) || !std::isfinite(options.captureRange))
    throw Error("capture range must be a positive number of mm (got " + std::to_string(options.captureRange) + ")");
}

EdgeField::EdgeField(const Volume& image, const EdgeOptions& options, const MatrixX3& landmarks)
    : geometry_(image.geometry) {
  checkEdgeOptions(options);
  const std::vector<Vector3> gradient = smoothedGradient(image, options.sigma);
  const Volume magnitude = magnitudeOf(image.geometry, gradient);
  if (options.method == EdgeMethod::GradientMagnitude) {
    vectors_ = normalizedGradient(magnitude, std::vector<std::uint8_t>(magnitude.voxels.size(), 1));
    return;
  }
  scale_ = edgeScale(magnitude, options, landmarks);
  edges_ = edgeMap(magnitude, gradient, scale_);
  // P = -distance to the nearest edge (see the header).
  edgeDistance_ = Volume{edges_.geometry, distanceTo(edges_)};
  hasEdges_ = edges_.count() > 0;
  Volume potential = edgeDistance_;
  std::vector<std::uint8_t> keep(potential.voxels.size());
  for (std::size_t v = 0; v < keep.size(); ++v) {
    keep[v] = potential.voxels[v] <= options.captureRange ? 1 : 0;
    potential.voxels[v] = -potential.voxels[v];
  }
  vectors_ = normalizedGradient(potential, keep);
}

double EdgeField::slopeBound() const { return 2.0 / geometry_.spacing.minCoeff(); }

double EdgeField::edgeDistance(const Vector3& point) const {
  if (!hasEdges_) return std::numeric_limits<double>::infinity();
  const Vector3 index = geometry_.toIndex(point);
  return geometry_.spans(index) ? edgeDistance_.interpolate(index) : std::numeric_limits<double>::infinity();
}

MatrixX3 EdgeField::sample(const MatrixX3& points) const {
  MatrixX3 result = MatrixX3::Zero(points.rows(), 3);
  const Matrix3 toIndex = geometry_.indexFromPhysical();
  const float* vectors = vectors_.data();
  for (Eigen::Index p = 0; p < points.rows(); ++p) {
    const Vector3 index = toIndex * (points.row(p).transpose() - geometry_.origin);
    if (!geometry_.spans(index)) continue;
    // Volume::interpolate's weights and sums (trilinearAt), for the three
    // components at once.
    const Trilinear corners = trilinearAt(geometry_, index);
    double sum[3] = {0.0, 0.0, 0.0};
    for (int c = 0; c < 8; ++c) {
      if (corners.weight[c] == 0) continue;
      const float* v = vectors + 3 * corners.offset[c];
      for (int a = 0; a < 3; ++a) sum[a] += corners.weight[c] * v[a];
    }
    for (int a = 0; a < 3; ++a) result(p, a) = sum[a];
  }
  return result;
}

}  // namespace dynsub
