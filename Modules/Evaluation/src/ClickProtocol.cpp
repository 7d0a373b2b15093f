#include "dynsub/ClickProtocol.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "dynsub/Error.h"

namespace dynsub {

namespace {

// The two in-slice axes of a slice across `axis`.
std::array<int, 2> inPlaneAxes(int axis) {
  if (axis == 0) return {1, 2};
  if (axis == 1) return {0, 2};
  return {0, 1};
}

bool inside(const Mask& m, std::array<int, 3> v) {
  return m.geometry.contains(v[0], v[1], v[2]) && m.voxels[m.geometry.offset(v[0], v[1], v[2])] != 0;
}

// Boundary points of the structure on slice `index` across `axis`
// (continuous indices), each with its in-slice outward direction (index axes).
struct BoundaryPoint {
  Vector3 index;
  Vector3 outward;
};

std::vector<BoundaryPoint> sliceBoundary(const Mask& m, int axis, int index) {
  const auto [a, b] = inPlaneAxes(axis);
  std::vector<BoundaryPoint> points;
  const auto& size = m.geometry.size;
  for (int y = 0; y < size[b]; ++y)
    for (int x = 0; x < size[a]; ++x) {
      std::array<int, 3> v{};
      v[axis] = index;
      v[a] = x;
      v[b] = y;
      if (!inside(m, v)) continue;
      for (const auto& [da, db] : {std::pair{1, 0}, {-1, 0}, {0, 1}, {0, -1}}) {
        std::array<int, 3> n = v;
        n[a] += da;
        n[b] += db;
        // Where the structure meets the image's side there is nothing to click:
        // that side is the field of view's, not the structure's.
        if (inside(m, n) || !m.geometry.contains(n[0], n[1], n[2])) continue;
        Vector3 outward = Vector3::Zero();
        outward[a] = da;
        outward[b] = db;
        points.push_back({Vector3(v[0], v[1], v[2]) + 0.5 * outward, outward});
      }
    }
  return points;
}

}  // namespace

void checkClickProtocol(const ClickProtocol& p) {
  const std::string name = "click protocol '" + p.name + "': ";
  if (p.axis < 0 || p.axis > 2) throw Error(name + "the axis must be 0 (sagittal), 1 (coronal) or 2 (axial)");
  if (p.seedOnly) {
    if (!(p.seedDepth > 0 && p.seedDepth <= 1)) throw Error(name + "the seed click's depth must be in (0, 1]");
    return;
  }
  if (p.slices < 1 || p.slices > 100) throw Error(name + "slices must be in 1..100");
  if (p.pointsPerSlice < 1 || p.pointsPerSlice > 100) throw Error(name + "points per slice must be in 1..100");
  if (!(p.coverageLow > 0 && p.coverageLow <= p.coverageHigh && p.coverageHigh <= 1))
    throw Error(name + "coverage must satisfy 0 < low <= high <= 1");
  // Beyond this a click's scatter or a mistake's distance exceeds any
  // structure's size, and the clicks fall outside it, or the image.
  constexpr double kLargestDistance = 100.0;
  const std::string range = " must be in 0.." + std::to_string(static_cast<int>(kLargestDistance)) + " mm";
  if (!(p.scatter >= 0 && p.scatter <= kLargestDistance)) throw Error(name + "scatter" + range);
  if (p.mistakes < 0 || p.mistakes > p.slices * p.pointsPerSlice)
    throw Error(name + "mistakes must be in 0..the number of clicks");
  if (!(p.mistakeDistance >= 0 && p.mistakeDistance <= kLargestDistance))
    throw Error(name + "the mistake distance" + range);
}

std::vector<Landmark> expertClicks(const Mask& reference, const ClickProtocol& protocol, unsigned seed) {
  checkClickProtocol(protocol);
  if (protocol.seedOnly) return {};
  const ImageGeometry& g = reference.geometry;
  const int axis = protocol.axis;
  // The structure's extent along the axis (voxel indices).
  int first = std::numeric_limits<int>::max(), last = -1;
  for (int k = 0; k < g.size[2]; ++k)
    for (int j = 0; j < g.size[1]; ++j)
      for (int i = 0; i < g.size[0]; ++i)
        if (reference.voxels[g.offset(i, j, k)]) {
          const int at = axis == 0 ? i : axis == 1 ? j : k;
          first = std::min(first, at);
          last = std::max(last, at);
        }
  if (last < 0) throw Error("the reference structure is empty");

  std::mt19937_64 random(seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const double extent = last - first + 1;
  const double coverage = protocol.coverageLow + (protocol.coverageHigh - protocol.coverageLow) * unit(random);
  const double span = coverage * extent;
  // Both ends go unclicked: each keeps 25-75 % of the unclicked part.
  const double start = first - 0.5 + (extent - span) * (0.25 + 0.5 * unit(random));
  // Slices at the centres of `slices` equal parts of the covered span.
  std::vector<int> indices;
  for (int s = 0; s < protocol.slices; ++s) {
    const int index = static_cast<int>(std::lround(start + (s + 0.5) * span / protocol.slices));
    if (indices.empty() || indices.back() != index) indices.push_back(std::clamp(index, first, last));
  }

  const auto [a, b] = inPlaneAxes(axis);
  // No draw at all without scatter (a normal distribution needs a spread > 0).
  std::normal_distribution<double> error(0.0, std::max(protocol.scatter, 1e-300));
  auto handError = [&] { return protocol.scatter > 0 ? error(random) : 0.0; };
  std::vector<Landmark> clicks;
  std::vector<Vector3> outwards;  // per click, LPS unit vectors
  for (int index : indices) {
    const std::vector<BoundaryPoint> boundary = sliceBoundary(reference, axis, index);
    if (static_cast<int>(boundary.size()) < protocol.pointsPerSlice)
      throw Error("the reference has " + std::to_string(boundary.size()) + " boundary points on slice " +
                  std::to_string(index) + ", fewer than the " + std::to_string(protocol.pointsPerSlice) +
                  " clicks asked for");
    // Farthest-point sampling in mm from a random first point.
    std::vector<Vector3> physical;
    for (const BoundaryPoint& p : boundary) physical.push_back(g.toPhysical(p.index));
    std::vector<double> nearest(physical.size(), std::numeric_limits<double>::infinity());
    size_t pick = static_cast<size_t>(unit(random) * physical.size()) % physical.size();
    for (int n = 0; n < protocol.pointsPerSlice; ++n) {
      Vector3 at = boundary[pick].index;
      // A hand's error, in the slice's plane (index units scaled to mm).
      at[a] += handError() / g.spacing[a];
      at[b] += handError() / g.spacing[b];
      clicks.push_back({"", g.toPhysical(at)});
      outwards.push_back((g.direction * boundary[pick].outward).normalized());
      for (size_t i = 0; i < physical.size(); ++i)
        nearest[i] = std::min(nearest[i], (physical[i] - physical[pick]).norm());
      pick = static_cast<size_t>(std::max_element(nearest.begin(), nearest.end()) - nearest.begin());
    }
  }
  // Mistaken clicks: some clicks moved off the boundary, in or out across it.
  std::vector<size_t> order(clicks.size());
  for (size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::shuffle(order.begin(), order.end(), random);
  for (int m = 0; m < protocol.mistakes && m < static_cast<int>(order.size()); ++m) {
    const double side = unit(random) < 0.5 ? -1.0 : 1.0;
    clicks[order[m]].position += side * protocol.mistakeDistance * outwards[order[m]];
  }
  // A viewer places points on the image only: a hand's error or a mistake
  // beyond the image's side stops at its last voxel.
  for (Landmark& click : clicks) {
    Vector3 index = g.toIndex(click.position);
    for (int d = 0; d < 3; ++d) index[d] = std::clamp(index[d], 0.0, g.size[d] - 1.0);
    click.position = g.toPhysical(index);
  }
  for (size_t i = 0; i < clicks.size(); ++i) clicks[i].label = "C-" + std::to_string(i + 1);
  return clicks;
}

Vector3 seedClick(const Mask& reference, double depthFraction, unsigned seed) {
  if (!(depthFraction > 0 && depthFraction <= 1)) throw Error("the seed click's depth must be in (0, 1]");
  const ImageGeometry& g = reference.geometry;
  // Depth: city-block distance (in voxels) to the nearest voxel outside, by
  // two sweeps; the deepest voxel, nearest the centroid among ties.
  const long long n = g.voxelCount();
  std::vector<int> depth(n);
  Vector3 centroid = Vector3::Zero();
  long long count = 0;
  for (int k = 0; k < g.size[2]; ++k)
    for (int j = 0; j < g.size[1]; ++j)
      for (int i = 0; i < g.size[0]; ++i) {
        const long long o = g.offset(i, j, k);
        if (!reference.voxels[o]) {
          depth[o] = 0;
          continue;
        }
        centroid += Vector3(i, j, k);
        ++count;
        int d = std::numeric_limits<int>::max() / 2;
        d = std::min(d, i > 0 ? depth[g.offset(i - 1, j, k)] + 1 : 1);  // outside the image is outside
        d = std::min(d, j > 0 ? depth[g.offset(i, j - 1, k)] + 1 : 1);
        d = std::min(d, k > 0 ? depth[g.offset(i, j, k - 1)] + 1 : 1);
        depth[o] = d;
      }
  if (count == 0) throw Error("the reference structure is empty");
  centroid /= static_cast<double>(count);
  for (int k = g.size[2] - 1; k >= 0; --k)
    for (int j = g.size[1] - 1; j >= 0; --j)
      for (int i = g.size[0] - 1; i >= 0; --i) {
        const long long o = g.offset(i, j, k);
        if (!depth[o]) continue;
        int d = depth[o];
        d = std::min(d, i + 1 < g.size[0] ? depth[g.offset(i + 1, j, k)] + 1 : 1);
        d = std::min(d, j + 1 < g.size[1] ? depth[g.offset(i, j + 1, k)] + 1 : 1);
        d = std::min(d, k + 1 < g.size[2] ? depth[g.offset(i, j, k + 1)] + 1 : 1);
        depth[o] = d;
      }
  Vector3 best = Vector3::Zero();
  int deepest = 0;
  double nearestCentroid = std::numeric_limits<double>::infinity();
  for (int k = 0; k < g.size[2]; ++k)
    for (int j = 0; j < g.size[1]; ++j)
      for (int i = 0; i < g.size[0]; ++i) {
        const int d = depth[g.offset(i, j, k)];
        const double c = (Vector3(i, j, k) - centroid).squaredNorm();
        if (d > deepest || (d == deepest && d > 0 && c < nearestCentroid)) {
          deepest = d;
          nearestCentroid = c;
          best = Vector3(i, j, k);
        }
      }
  if (depthFraction >= 1) return g.toPhysical(best);
  const int least = std::max(1, static_cast<int>(std::ceil(depthFraction * deepest)));
  std::vector<Vector3> deepEnough;
  for (int k = 0; k < g.size[2]; ++k)
    for (int j = 0; j < g.size[1]; ++j)
      for (int i = 0; i < g.size[0]; ++i)
        if (depth[g.offset(i, j, k)] >= least) deepEnough.push_back(Vector3(i, j, k));
  std::mt19937_64 random(seed);
  return g.toPhysical(deepEnough[std::uniform_int_distribution<size_t>(0, deepEnough.size() - 1)(random)]);
}

}  // namespace dynsub
