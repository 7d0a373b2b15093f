// smoothedGradientIn (the gradient on a small box, sampled Gaussians) against
// smoothedGradient (ITK's recursive filters on the whole image), on real MRI.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "dynsub/ImageFilters.h"
#include "dynsub/ImageIO.h"

namespace dynsub {
namespace {

// The largest difference of the two at the box's voxels, over the largest
// magnitude the whole image's gradient has in the box.
double relativeDifference(const Volume& image, double sigma, const std::array<int, 3>& first,
                          const std::array<int, 3>& size) {
  const std::vector<Vector3> whole = smoothedGradient(image, sigma);
  const std::vector<Vector3> box = smoothedGradientIn(image, sigma, first, size);
  EXPECT_EQ(box.size(), static_cast<std::size_t>(size[0]) * size[1] * size[2]);
  double largest = 0, difference = 0;
  std::size_t v = 0;
  for (int k = 0; k < size[2]; ++k)
    for (int j = 0; j < size[1]; ++j)
      for (int i = 0; i < size[0]; ++i, ++v) {
        const Vector3& theirs = whole[image.geometry.offset(first[0] + i, first[1] + j, first[2] + k)];
        largest = std::max(largest, theirs.norm());
        difference = std::max(difference, (box[v] - theirs).norm());
      }
  return difference / largest;
}

TEST(SmoothedGradientIn, AgreesWithTheRecursiveFilterOnColin27) {
  // Colin27 around the left caudate, cropped with a margin of 6 sigma so that
  // the recursive filter's own boundary is far from the box; and the box at
  // the crop's corner, where both repeat the image beyond its faces. The
  // two approximate one Gaussian differently (Deriche's recursive filter is
  // a fourth-order fit to it; the sampled kernel is cut at 4 sigma): they
  // differ by 0.6 to 1.0 % of the largest magnitude at sigma 1 and 2 mm,
  // and 1.5 % is the bound.
  const Volume colin = readVolume("/usr/share/mricron/templates/ch2.nii.gz");
  const Volume crop = cropVolume(colin, {90 - 25, 126 + 0, 72 + 0}, {40, 50, 40});
  for (const double sigma : {1.0, 2.0}) {
    SCOPED_TRACE("sigma " + std::to_string(sigma));
    EXPECT_LT(relativeDifference(crop, sigma, {14, 20, 14}, {12, 10, 12}), 0.015);
    EXPECT_LT(relativeDifference(crop, sigma, {0, 0, 0}, {5, 5, 5}), 0.015);
  }
}

TEST(SmoothedGradientIn, IsTheRampsSlopeInLpsOnAnObliqueAnisotropicGrid) {
  // A linear image's smoothed gradient is its slope, whatever the grid: the
  // axes turned, voxels of 0.7 x 1 x 2.5 mm. Exact to rounding inside the
  // image, where no face is repeated.
  Volume ramp;
  ramp.geometry.size = {30, 25, 14};
  ramp.geometry.spacing = Vector3(0.7, 1.0, 2.5);
  ramp.geometry.origin = Vector3(4, -2, 9);
  ramp.geometry.direction = Eigen::AngleAxisd(0.4, Vector3(1, 2, 3).normalized()).toRotationMatrix();
  const Vector3 slope(0.3, -1.2, 0.5);  // per mm, LPS
  ramp.voxels.resize(ramp.geometry.voxelCount());
  for (int k = 0; k < 14; ++k)
    for (int j = 0; j < 25; ++j)
      for (int i = 0; i < 30; ++i)
        ramp.voxels[ramp.geometry.offset(i, j, k)] =
            static_cast<float>(slope.dot(ramp.geometry.toPhysical(Vector3(i, j, k))));
  const std::vector<Vector3> gradient = smoothedGradientIn(ramp, 1.5, {10, 8, 5}, {3, 3, 3});
  for (const Vector3& g : gradient) EXPECT_LT((g - slope).norm(), 1e-4) << g.transpose();
}

}  // namespace
}  // namespace dynsub
