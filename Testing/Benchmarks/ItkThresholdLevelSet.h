#pragma once
// ITK's threshold level set (ThresholdSegmentationLevelSetImageFilter), the
// region snake of ITK-SNAP: the front grows where the intensity lies inside
// [lower, upper] and shrinks outside, with a curvature term. The baseline the
// fast engine is timed against. Plain arrays only (see ItkGeodesicActiveContour.h).
#include <array>
#include <cstdint>
#include <vector>

#include "ItkBridge.h"

namespace itkbaseline {

using dynsub::itkbridge::Geometry;

struct ThresholdLevelSetOptions {
  // The intensity window: mean -/+ `window` standard deviations of the
  // intensities inside the initial mask (the structure's own tissue); or,
  // with window <= 0, from the boundary the expert marked: the mean intensity
  // of the edge voxels darker than that inside mean (lower) and of those
  // brighter (upper).
  double window = 2.0;
  double propagation = 1.0;
  double curvature = 1.0;
  double maximumRmsError = 0.02;
  int iterations = 1200;
};

struct ThresholdLevelSetResult {
  std::vector<std::uint8_t> mask;  // 1 inside the final front
  double lower = 0, upper = 0;     // the intensity window used
  int elapsedIterations = 0;
  double seconds = 0;  // whole pipeline: statistics, distance map, evolution, threshold
};

// The initial level set is the signed distance to the initial mask's boundary.
ThresholdLevelSetResult thresholdLevelSet(const Geometry& grid, const std::vector<float>& image,
                                          const std::vector<std::uint8_t>& initialMask,
                                          const std::vector<std::array<int, 3>>& edgeVoxels,
                                          const ThresholdLevelSetOptions& options);

}  // namespace itkbaseline
