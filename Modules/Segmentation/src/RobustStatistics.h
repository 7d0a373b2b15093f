#pragma once
// Private to the Segmentation module: the median and the robust spread of a
// sample (1.4826 x the median absolute deviation, which is the standard
// deviation for normal data and ignores outliers up to half the sample), the
// appearance both the region pressure and the seed's growth learn.
#include <algorithm>
#include <cmath>
#include <optional>
#include <vector>

#include "dynsub/ControlMesh.h"
#include "dynsub/Volume.h"

namespace dynsub {

struct RobustStatistics {
  double median = 0, spread = 0;
};

// `values` must not be empty.
inline RobustStatistics robustStatistics(std::vector<double> values) {
  auto median = [](std::vector<double>& v) {
    std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
    return v[v.size() / 2];
  };
  RobustStatistics s;
  s.median = median(values);
  for (double& v : values) v = std::abs(v - s.median);
  s.spread = 1.4826 * median(values);
  return s;
}

// The appearance inside a closed model: the median and spread of the
// image's intensities at the voxel centres the model's limit surface encloses
// (voxelized on the part of the grid it covers); none when it encloses no
// voxel centre.
std::optional<RobustStatistics> insideIntensities(const Volume& image, const ControlMesh& model);

// The 99th percentile of the gradient magnitude (central differences, per
// mm) over every second voxel of `image` in each direction: how fast the
// intensity under a moving surface can change, bar the steepest voxels. What
// the pressures' slopes are bounded with, to stabilize time steps.
double steepGradient(const Volume& image);

}  // namespace dynsub
