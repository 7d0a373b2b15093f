#include "dynsub/RegionGrowing.h"

#include <algorithm>
#include <array>
#include <limits>
#include <utility>

#include "dynsub/ImageFilters.h"

namespace dynsub {

namespace {

// Marks in `reached` the voxels of `allowed` 6-connected to `starts` (marked
// already) that it has not marked; returns how many it marked, the starts
// included.
long long flood(const std::vector<std::uint8_t>& allowed, const ImageGeometry& g, std::vector<long long> starts,
                std::vector<std::uint8_t>& reached) {
  long long marked = static_cast<long long>(starts.size());
  std::vector<long long> stack = std::move(starts);
  const long long sx = 1, sy = g.size[0], sz = static_cast<long long>(g.size[0]) * g.size[1];
  while (!stack.empty()) {
    const long long o = stack.back();
    stack.pop_back();
    const int i = static_cast<int>(o % sy), j = static_cast<int>((o / sy) % g.size[1]),
              k = static_cast<int>(o / sz);
    const std::pair<bool, long long> neighbours[6] = {{i > 0, o - sx},           {i + 1 < g.size[0], o + sx},
                                                      {j > 0, o - sy},           {j + 1 < g.size[1], o + sy},
                                                      {k > 0, o - sz},           {k + 1 < g.size[2], o + sz}};
    for (const auto& [inside, n] : neighbours)
      if (inside && allowed[n] && !reached[n]) {
        reached[n] = 1;
        ++marked;
        stack.push_back(n);
      }
  }
  return marked;
}

}  // namespace

std::vector<std::uint8_t> connectedTo(const std::vector<std::uint8_t>& allowed, const ImageGeometry& g,
                                      std::vector<long long> starts) {
  std::vector<std::uint8_t> reached(allowed.size(), 0);
  for (long long start : starts) reached[start] = 1;
  flood(allowed, g, std::move(starts), reached);
  return reached;
}

std::vector<long long> pieceSizes(const std::vector<std::uint8_t>& region, const ImageGeometry& grid) {
  std::vector<std::uint8_t> reached(region.size(), 0);
  std::vector<long long> sizes;
  for (std::size_t v = 0; v < region.size(); ++v) {
    if (!region[v] || reached[v]) continue;
    reached[v] = 1;
    sizes.push_back(flood(region, grid, {static_cast<long long>(v)}, reached));
  }
  std::sort(sizes.rbegin(), sizes.rend());
  return sizes;
}

namespace {

// An index box {first, size} (Volume.h: occupiedRegion).
using IndexBox = std::pair<std::array<int, 3>, std::array<int, 3>>;

// distanceTo(features) at the voxels of `box` (infinity elsewhere), computed
// on that box alone. Exact wherever the nearest feature voxel lies in the
// box: the callers ask only at voxels of a region whose box (occupiedRegion,
// a margin of one voxel) holds every feature or is ringed by them. A seed's
// region is often a tenth of its 120 mm box.
std::vector<float> distanceInBox(const std::vector<std::uint8_t>& features, const ImageGeometry& g,
                                 const IndexBox& box) {
  std::vector<float> distance(features.size(), std::numeric_limits<float>::infinity());
  const auto& [first, size] = box;
  if (size[0] == 0) return distance;
  const Mask part = cropMask(Mask{g, features}, first, size);
  const std::vector<float> inBox = distanceTo(part);
  const ImageGeometry& b = part.geometry;
  for (int k = 0; k < b.size[2]; ++k)
    for (int j = 0; j < b.size[1]; ++j)
      std::copy_n(inBox.begin() + b.offset(0, j, k), b.size[0],
                  distance.begin() + g.offset(first[0], first[1] + j, first[2] + k));
  return distance;
}

}  // namespace

std::vector<float> depthInside(const std::vector<std::uint8_t>& grown, const ImageGeometry& g) {
  const long long n = g.voxelCount();
  std::vector<std::uint8_t> outside(n);
  for (long long o = 0; o < n; ++o) outside[o] = !grown[o];
  // The box around `grown` is ringed by outside voxels (or by the grid's
  // side, as the whole grid is): each grown voxel's nearest one is in it.
  return distanceInBox(outside, g, occupiedRegion(g, grown, 1));
}

std::vector<std::uint8_t> coreOf(const std::vector<std::uint8_t>& grown, const std::vector<float>& depth,
                                 double radius) {
  std::vector<std::uint8_t> core(grown.size());
  for (std::size_t o = 0; o < grown.size(); ++o) core[o] = grown[o] && depth[o] > radius;
  return core;
}

std::vector<std::uint8_t> openFrom(const std::vector<std::uint8_t>& grown, const std::vector<std::uint8_t>& core,
                                   const ImageGeometry& g, double radius, std::vector<long long> coreStarts) {
  // The core lies inside `grown`, so inside its box.
  const std::vector<float> away =
      distanceInBox(connectedTo(core, g, std::move(coreStarts)), g, occupiedRegion(g, grown, 1));
  std::vector<std::uint8_t> kept(grown.size());
  for (std::size_t o = 0; o < grown.size(); ++o) kept[o] = grown[o] && away[o] <= radius;
  return kept;
}

std::vector<std::uint8_t> fillHoles(const std::vector<std::uint8_t>& region, const ImageGeometry& g) {
  const long long n = g.voxelCount();
  std::vector<std::uint8_t> outside(n);
  std::vector<long long> border;
  for (int k = 0; k < g.size[2]; ++k)
    for (int j = 0; j < g.size[1]; ++j)
      for (int i = 0; i < g.size[0]; ++i) {
        const long long o = g.offset(i, j, k);
        outside[o] = !region[o];
        if (outside[o] && (i == 0 || j == 0 || k == 0 || i + 1 == g.size[0] || j + 1 == g.size[1] ||
                           k + 1 == g.size[2]))
          border.push_back(o);
      }
  const std::vector<std::uint8_t> reached = connectedTo(outside, g, std::move(border));
  std::vector<std::uint8_t> filled(n);
  for (long long o = 0; o < n; ++o) filled[o] = !reached[o];
  return filled;
}

std::vector<Vector3> boundaryFaces(const std::vector<std::uint8_t>& region, const ImageGeometry& g,
                                   bool* touchesSide) {
  std::vector<Vector3> faces;
  *touchesSide = false;
  for (int k = 0; k < g.size[2]; ++k)
    for (int j = 0; j < g.size[1]; ++j)
      for (int i = 0; i < g.size[0]; ++i) {
        if (!region[g.offset(i, j, k)]) continue;
        const int step[6][3] = {{-1, 0, 0}, {1, 0, 0}, {0, -1, 0}, {0, 1, 0}, {0, 0, -1}, {0, 0, 1}};
        for (const auto& s : step) {
          const int a = i + s[0], b = j + s[1], c = k + s[2];
          if (!g.contains(a, b, c)) {  // the grid's side: the voxel itself (its face may be the image's edge)
            *touchesSide = true;
            faces.push_back(g.toPhysical(Vector3(i, j, k)));
            continue;
          }
          if (!region[g.offset(a, b, c)])
            faces.push_back(g.toPhysical(Vector3(i + 0.5 * s[0], j + 0.5 * s[1], k + 0.5 * s[2])));
        }
      }
  return faces;
}

std::vector<Vector3> farthestPointSample(const std::vector<Vector3>& points, const Vector3& start,
                                         std::size_t count) {
  std::vector<Vector3> taken;
  if (points.empty()) return taken;
  std::vector<double> gap(points.size(), std::numeric_limits<double>::infinity());
  std::size_t next = 0;
  for (std::size_t f = 1; f < points.size(); ++f)
    if ((points[f] - start).squaredNorm() < (points[next] - start).squaredNorm()) next = f;
  const std::size_t keep = std::min(points.size(), count);
  while (taken.size() < keep) {
    taken.push_back(points[next]);
    gap[next] = 0;
    std::size_t farthest = 0;
    for (std::size_t f = 0; f < points.size(); ++f) {
      gap[f] = std::min(gap[f], (points[f] - points[next]).squaredNorm());
      if (gap[f] > gap[farthest]) farthest = f;
    }
    next = farthest;
  }
  return taken;
}

}  // namespace dynsub
