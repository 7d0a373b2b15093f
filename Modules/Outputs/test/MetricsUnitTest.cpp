#include <gtest/gtest.h>

#include <cmath>

#include "TestGrids.h"
#include "dynsub/Error.h"
#include "dynsub/Metrics.h"

namespace dynsub {
namespace {

Mask box(const ImageGeometry& g, std::array<int, 3> first, std::array<int, 3> last) {
  Mask m{g, std::vector<std::uint8_t>(g.voxelCount(), 0)};
  for (int k = first[2]; k <= last[2]; ++k)
    for (int j = first[1]; j <= last[1]; ++j)
      for (int i = first[0]; i <= last[0]; ++i) m.voxels[g.offset(i, j, k)] = 1;
  return m;
}

TEST(Metrics, ShiftedCubesByHand) {
  // Two 10^3 cubes, the second shifted by one voxel (0.5 mm) along i.
  const ImageGeometry g = grid({16, 14, 14}, Vector3(0.5, 1.0, 2.0), Vector3::Zero(), Matrix3::Identity());
  const Mask a = box(g, {2, 2, 2}, {11, 11, 11}), b = box(g, {3, 2, 2}, {12, 11, 11});
  const OverlapMetrics m = compareMasks(a, b);
  EXPECT_DOUBLE_EQ(m.dice, 2.0 * 900 / 2000);
  EXPECT_DOUBLE_EQ(m.jaccard, 900.0 / 1100);
  EXPECT_DOUBLE_EQ(m.volumeDifferencePercent, 0.0);
  EXPECT_DOUBLE_EQ(m.volumeA, 1000 * 1.0);
  // Of each cube's 488 boundary voxels, 164 lie one voxel (0.5 mm) from the
  // other's boundary (its whole leading face and the 8 x 8 inside of its
  // trailing face); the rest are on it.
  EXPECT_NEAR(m.meanSurfaceDistance, 0.5 * 164.0 / 488.0, 1e-6);
  EXPECT_NEAR(m.hausdorff, 0.5, 1e-6);
  EXPECT_NEAR(m.hd95, 0.5, 1e-6);

  const OverlapMetrics same = compareMasks(a, a);
  EXPECT_DOUBLE_EQ(same.dice, 1.0);
  EXPECT_DOUBLE_EQ(same.hausdorff, 0.0);
  const Mask smaller = box(g, {2, 2, 2}, {6, 11, 11});
  EXPECT_DOUBLE_EQ(compareMasks(smaller, a).volumeDifferencePercent, -50.0);
  EXPECT_THROW(compareMasks(box(g, {0, 0, 0}, {-1, -1, -1}), a), Error);
}

// The surface distances are computed on the box around both masks (Metrics.cpp);
// against brute force over every pair of boundary voxels, for masks far from
// the border, touching it, and far apart, on an anisotropic grid.
TEST(Metrics, SurfaceDistancesAgreeWithBruteForce) {
  const ImageGeometry g = grid({24, 20, 18}, Vector3(0.7, 1.0, 1.3), Vector3::Zero(), Matrix3::Identity());
  auto boundary = [&](const Mask& m) {
    std::vector<Vector3> points;
    for (int k = 0; k < g.size[2]; ++k)
      for (int j = 0; j < g.size[1]; ++j)
        for (int i = 0; i < g.size[0]; ++i) {
          if (!m.voxels[g.offset(i, j, k)]) continue;
          bool edge = false;
          for (const auto& [a, b, c] : {std::array<int, 3>{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}}) {
            edge = edge || !g.contains(i + a, j + b, k + c) || !m.voxels[g.offset(i + a, j + b, k + c)];
          }
          if (edge) points.push_back(g.toPhysical(Vector3(i, j, k)));
        }
    return points;
  };
  const std::vector<std::pair<Mask, Mask>> cases = {
      {box(g, {5, 5, 5}, {12, 11, 10}), box(g, {7, 4, 6}, {14, 12, 9})},
      {box(g, {0, 0, 3}, {9, 8, 17}), box(g, {2, 1, 0}, {11, 19, 12})},
      {box(g, {1, 2, 2}, {4, 5, 5}), box(g, {18, 14, 12}, {23, 19, 16})}};
  for (const auto& [a, b] : cases) {
    const std::vector<Vector3> ba = boundary(a), bb = boundary(b);
    std::vector<double> distances;
    for (const auto& [from, to] : {std::pair{&ba, &bb}, std::pair{&bb, &ba}}) {
      for (const Vector3& p : *from) {
        double nearest = 1e300;
        for (const Vector3& q : *to) nearest = std::min(nearest, (p - q).norm());
        distances.push_back(nearest);
      }
    }
    double sum = 0.0;
    for (double d : distances) sum += d;
    std::sort(distances.begin(), distances.end());
    const OverlapMetrics m = compareMasks(a, b);
    // Maurer's transform is exact; the distances are stored as float.
    EXPECT_NEAR(m.meanSurfaceDistance, sum / distances.size(), 1e-5);
    EXPECT_NEAR(m.hausdorff, distances.back(), 1e-5);
    EXPECT_NEAR(m.hd95, distances[static_cast<size_t>(std::ceil(0.95 * distances.size())) - 1], 1e-5);
  }
}

}  // namespace
}  // namespace dynsub
