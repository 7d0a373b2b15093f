#include "dynsub/Metrics.h"

#include <algorithm>
#include <array>
#include <cmath>

#include "dynsub/Error.h"
#include "dynsub/ImageFilters.h"

namespace dynsub {
namespace {

Mask boundaryOf(const Mask& mask) {
  const ImageGeometry& g = mask.geometry;
  Mask boundary{g, std::vector<std::uint8_t>(mask.voxels.size(), 0)};
  const int steps[6][3] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
  for (int k = 0; k < g.size[2]; ++k)
    for (int j = 0; j < g.size[1]; ++j)
      for (int i = 0; i < g.size[0]; ++i) {
        const long long v = g.offset(i, j, k);
        if (!mask.voxels[v]) continue;
        for (const auto& s : steps) {
          const int a = i + s[0], b = j + s[1], c = k + s[2];
          if (!g.contains(a, b, c) || !mask.voxels[g.offset(a, b, c)]) {
            boundary.voxels[v] = 1;
            break;
          }
        }
      }
  return boundary;
}

}  // namespace

OverlapMetrics compareMasks(const Mask& a, const Mask& b) {
  if (!a.geometry.sameGridAs(b.geometry)) throw Error("cannot compare masks on different grids");
  OverlapMetrics m;
  long long both = 0;
  for (std::size_t v = 0; v < a.voxels.size(); ++v) {
    m.voxelsA += a.voxels[v];
    m.voxelsB += b.voxels[v];
    both += a.voxels[v] & b.voxels[v];
  }
  if (m.voxelsA == 0) throw Error("cannot compare masks: the segmentation is empty");
  if (m.voxelsB == 0) throw Error("cannot compare masks: the reference is empty");
  const double voxelVolume = a.geometry.spacing.prod();
  m.volumeA = m.voxelsA * voxelVolume;
  m.volumeB = m.voxelsB * voxelVolume;
  m.dice = 2.0 * both / (m.voxelsA + m.voxelsB);
  m.jaccard = static_cast<double>(both) / (m.voxelsA + m.voxelsB - both);
  m.volumeDifferencePercent = 100.0 * (m.voxelsA - m.voxelsB) / m.voxelsB;

  // The surface distances only involve the two masks' boundaries, so they
  // are computed on the box around both, one voxel wider on every side
  // (clamped to the image): a mask voxel on that box's edge is then on the
  // image's edge too, so the boundaries are the same voxels, and the exact
  // distance maps agree wherever they are read. Over a whole image the
  // distance maps would take most of a segmentation's time.
  const ImageGeometry& g = a.geometry;
  std::vector<std::uint8_t> either(a.voxels.size());
  for (std::size_t v = 0; v < either.size(); ++v) either[v] = a.voxels[v] | b.voxels[v];
  const auto [first, size] = occupiedRegion(g, either, 1);
  const Mask partA = cropMask(a, first, size), partB = cropMask(b, first, size);
  const Mask boundaryA = boundaryOf(partA), boundaryB = boundaryOf(partB);
  const std::vector<float> toA = distanceTo(boundaryA), toB = distanceTo(boundaryB);
  std::vector<double> distances;
  for (std::size_t v = 0; v < partA.voxels.size(); ++v) {
    if (boundaryA.voxels[v]) distances.push_back(toB[v]);
    if (boundaryB.voxels[v]) distances.push_back(toA[v]);
  }
  double sum = 0;
  for (double d : distances) sum += d;
  m.meanSurfaceDistance = sum / distances.size();
  std::sort(distances.begin(), distances.end());
  m.hausdorff = distances.back();
  // Nearest-rank 95th percentile.
  const std::size_t rank = static_cast<std::size_t>(std::ceil(0.95 * distances.size()));
  m.hd95 = distances[std::max<std::size_t>(rank, 1) - 1];
  return m;
}

}  // namespace dynsub
