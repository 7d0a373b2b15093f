// distanceTo (ImageFilters.h), DynSub's own exact distance transform, against
// ITK's Maurer transform (the module's bridge, which it replaced).
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "BridgeGeometry.h"
#include "dynsub/ImageFilters.h"

namespace dynsub {
namespace {

Mask randomMask(const std::array<int, 3>& size, const Vector3& spacing, double share, unsigned seed) {
  Mask m;
  m.geometry.size = size;
  m.geometry.spacing = spacing;
  m.geometry.origin = Vector3(-3.5, 2.0, 7.25);
  std::mt19937 random(seed);
  std::bernoulli_distribution on(share);
  m.voxels.resize(m.geometry.voxelCount());
  for (auto& v : m.voxels) v = on(random);
  return m;
}

std::vector<float> itksDistances(const Mask& m) {
  return itkbridge::distanceMap(toBridge(m.geometry), m.voxels);
}

TEST(DistanceTo, EqualsItksMaurerTransformToTheBitOnOneAndHalfMillimetreGrids) {
  // Squared distances on these grids are sums of squares of multiples of
  // 0.5 mm, which both transforms hold exactly: no rounding to differ by.
  for (const Vector3& spacing : {Vector3(1, 1, 1), Vector3(0.5, 0.5, 0.5), Vector3(1, 0.5, 1)})
    for (double share : {0.001, 0.02, 0.3})
      for (unsigned seed : {1u, 2u}) {
        SCOPED_TRACE("spacing " + std::to_string(spacing.y()) + ", share " + std::to_string(share));
        const Mask m = randomMask({37, 29, 23}, spacing, share, seed);
        const std::vector<float> ours = distanceTo(m), theirs = itksDistances(m);
        ASSERT_EQ(ours.size(), theirs.size());
        long long differing = 0;
        for (std::size_t v = 0; v < ours.size(); ++v) differing += ours[v] != theirs[v];
        EXPECT_EQ(differing, 0);
      }
}

TEST(DistanceTo, AgreesWithItkOnAnisotropicGridsAndIsExact) {
  // Elsewhere both keep squared distances in floats, rounded differently:
  // within a float's rounding (1e-6 relative) of ITK and of brute force in
  // doubles.
  const Mask m = randomMask({21, 17, 13}, Vector3(0.8, 1.0, 1.25), 0.01, 3);
  const std::vector<float> ours = distanceTo(m), theirs = itksDistances(m);
  const ImageGeometry& g = m.geometry;
  for (int k = 0; k < g.size[2]; ++k)
    for (int j = 0; j < g.size[1]; ++j)
      for (int i = 0; i < g.size[0]; ++i) {
        const long long v = g.offset(i, j, k);
        double nearest = std::numeric_limits<double>::infinity();
        for (int c = 0; c < g.size[2]; ++c)
          for (int b = 0; b < g.size[1]; ++b)
            for (int a = 0; a < g.size[0]; ++a)
              if (m.voxels[g.offset(a, b, c)])
                nearest = std::min(nearest, std::hypot((i - a) * 0.8, (j - b) * 1.0, (k - c) * 1.25));
        ASSERT_NEAR(ours[v], nearest, 1e-6 * std::max(1.0, nearest)) << i << " " << j << " " << k;
        ASSERT_NEAR(ours[v], theirs[v], 1e-6 * std::max(1.0f, theirs[v])) << i << " " << j << " " << k;
      }
}

TEST(DistanceTo, AnEmptyMaskIsInfinitelyFarAndOneVoxelIsZeroOnItself) {
  Mask m = randomMask({9, 8, 7}, Vector3::Ones(), 0.0, 1);
  for (float d : distanceTo(m)) EXPECT_TRUE(std::isinf(d));
  m.voxels[m.geometry.offset(2, 3, 4)] = 1;
  const std::vector<float> d = distanceTo(m);
  EXPECT_EQ(d[m.geometry.offset(2, 3, 4)], 0.0f);
  EXPECT_EQ(d[m.geometry.offset(8, 7, 6)], static_cast<float>(std::sqrt(36.0 + 16.0 + 4.0)));
}

}  // namespace
}  // namespace dynsub
