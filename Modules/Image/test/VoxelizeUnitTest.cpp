#include <gtest/gtest.h>

#include <algorithm>
#include <climits>
#include <cmath>
#include <string>
#include <utility>
#include <vector>

#include "TestGrids.h"
#include "dynsub/Error.h"
#include "dynsub/Volume.h"
#include "dynsub/Voxelize.h"

namespace dynsub {
namespace {

// A closed UV sphere (triangles oriented outward).
void uvSphere(const Vector3& centre, double radius, MatrixX3& points, std::vector<std::array<int, 3>>& triangles) {
  const int rings = 60, sectors = 120;
  points.resize(2 + (rings - 1) * sectors, 3);
  points.row(0) = (centre + Vector3(0, 0, radius)).transpose();
  points.row(1) = (centre - Vector3(0, 0, radius)).transpose();
  for (int r = 1; r < rings; ++r)
    for (int s = 0; s < sectors; ++s) {
      const double theta = M_PI * r / rings, phi = 2 * M_PI * s / sectors;
      points.row(2 + (r - 1) * sectors + s) =
          (centre + radius * Vector3(std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi),
                                     std::cos(theta)))
              .transpose();
    }
  auto at = [&](int r, int s) { return 2 + (r - 1) * sectors + (s % sectors); };
  triangles.clear();
  for (int s = 0; s < sectors; ++s) {
    triangles.push_back({0, at(1, s), at(1, s + 1)});
    triangles.push_back({1, at(rings - 1, s + 1), at(rings - 1, s)});
    for (int r = 1; r + 1 < rings; ++r) {
      triangles.push_back({at(r, s), at(r + 1, s), at(r + 1, s + 1)});
      triangles.push_back({at(r, s), at(r + 1, s + 1), at(r, s + 1)});
    }
  }
}

// A grid that is not another's says how, so that a user knows what to resample.
TEST(ImageGeometry, ItsDifferenceFromAnotherGridIsNamed) {
  ImageGeometry image;
  image.size = {181, 217, 181};
  EXPECT_EQ(image.differenceFrom(image, "image"), "");
  ImageGeometry other = image;
  other.size = {91, 109, 91};
  EXPECT_EQ(other.differenceFrom(image, "image"),
            "its size is 91 x 109 x 91 voxels, where the image's is 181 x 217 x 181");
  other = image;
  other.spacing = Vector3(2, 2, 2);
  EXPECT_EQ(other.differenceFrom(image, "image"), "its spacing is (2, 2, 2) mm, where the image's is (1, 1, 1)");
  other = image;
  other.direction(0, 0) = -1;
  EXPECT_EQ(other.differenceFrom(image, "image"),
            "its axes point other ways than the image's (up to 180 degrees apart: a flipped, permuted or rotated "
            "copy)");
  other.spacing = Vector3(1.000002, 1, 1);  // beyond sameGridAs's 1e-6, and shown
  other.direction = image.direction;
  EXPECT_EQ(other.differenceFrom(image, "image"), "its spacing is (1.000002, 1, 1) mm, where the image's is (1, 1, 1)");
  other = image;
  other.origin = Vector3(-90, 126, -72);
  EXPECT_EQ(other.differenceFrom(image, "image"),
            "its origin is (-90, 126, -72) mm (LPS), where the image's is (0, 0, 0)");
}

TEST(Voxelize, SphereOnAnAnisotropicRotatedGrid) {
  const ImageGeometry g = grid({48, 40, 24}, Vector3(0.6, 0.8, 1.5), Vector3(-14, -15, -16), skewDirection());
  const Vector3 centre = g.toPhysical(Vector3(23.5, 19.5, 11.5));
  const double radius = 10.0;
  MatrixX3 points;
  std::vector<std::array<int, 3>> triangles;
  uvSphere(centre, radius, points, triangles);
  const Mask mask = voxelizeSurface(points, triangles, g);
  // Every voxel centre clearly inside or outside the sphere is classified so;
  // the polygon lies within radius (1 - cos(pi/60)) ~ 0.014 mm of the sphere.
  long long inside = 0;
  for (int k = 0; k < g.size[2]; ++k)
    for (int j = 0; j < g.size[1]; ++j)
      for (int i = 0; i < g.size[0]; ++i) {
        const double r = (g.toPhysical(Vector3(i, j, k)) - centre).norm();
        const bool set = mask.voxels[g.offset(i, j, k)];
        if (r < radius - 0.02) {
          ASSERT_TRUE(set) << i << ' ' << j << ' ' << k;
        }
        if (r > radius + 0.02) {
          ASSERT_FALSE(set) << i << ' ' << j << ' ' << k;
        }
        inside += set;
      }
  const double volume = inside * g.spacing.prod(), exact = 4.0 / 3.0 * M_PI * radius * radius * radius;
  EXPECT_NEAR(volume / exact, 1.0, 0.02);
}

// A surface that passes through itself: two spheres overlapping, as one
// triangle set. The surface winds twice around the lens they share, which is
// inside (the nonzero rule; the even-odd rule would leave it out). Turned
// inward, the spheres give the same mask.
TEST(Voxelize, WhereASurfaceOverlapsItselfIsInside) {
  const ImageGeometry g = grid({48, 40, 24}, Vector3(0.6, 0.8, 1.5), Vector3(-14, -15, -16), skewDirection());
  const Vector3 a = g.toPhysical(Vector3(18.5, 19.5, 11.5)), b = a + Vector3(6, 3, 2);
  const double radius = 8.0;
  MatrixX3 first, second;
  std::vector<std::array<int, 3>> firstTriangles, secondTriangles;
  uvSphere(a, radius, first, firstTriangles);
  uvSphere(b, radius, second, secondTriangles);
  MatrixX3 points(first.rows() + second.rows(), 3);
  points << first, second;
  std::vector<std::array<int, 3>> triangles = firstTriangles;
  const int shift = static_cast<int>(first.rows());
  for (const auto& t : secondTriangles) triangles.push_back({t[0] + shift, t[1] + shift, t[2] + shift});
  std::vector<std::array<int, 3>> inward = triangles;
  for (auto& t : inward) std::swap(t[1], t[2]);
  const Mask mask = voxelizeSurface(points, triangles, g);
  EXPECT_EQ(voxelizeSurface(points, inward, g).voxels, mask.voxels);
  // 0.02 mm: the polygons' distance from their spheres, as above.
  long long lens = 0;
  for (int k = 0; k < g.size[2]; ++k)
    for (int j = 0; j < g.size[1]; ++j)
      for (int i = 0; i < g.size[0]; ++i) {
        const Vector3 x = g.toPhysical(Vector3(i, j, k));
        const double near = std::min((x - a).norm(), (x - b).norm()), far = std::max((x - a).norm(), (x - b).norm());
        const bool set = mask.voxels[g.offset(i, j, k)];
        if (near < radius - 0.02) {
          ASSERT_TRUE(set) << i << ' ' << j << ' ' << k;
        }
        if (near > radius + 0.02) {
          ASSERT_FALSE(set) << i << ' ' << j << ' ' << k;
        }
        lens += far < radius - 0.02;
      }
  EXPECT_GT(lens, 500);  // the lens holds enough voxel centres to be tested
}

TEST(Voxelize, OpenSurfaceIsRefused) {
  const ImageGeometry g = grid({20, 20, 20}, Vector3::Ones(), Vector3::Zero(), Matrix3::Identity());
  MatrixX3 points;
  std::vector<std::array<int, 3>> triangles;
  uvSphere(Vector3(10, 10, 10), 5, points, triangles);
  // The last triangle twice (its edges used 3 times), or not at all (once):
  // the error names the first of its edges (lower point index first) and the
  // count.
  const std::array<int, 3> last = triangles.back();
  std::pair<int, int> lowest{INT_MAX, INT_MAX};
  for (int e = 0; e < 3; ++e)
    lowest = std::min(lowest, std::pair<int, int>(std::minmax(last[e], last[(e + 1) % 3])));
  const std::string firstEdge = "edge " + std::to_string(lowest.first) + "-" + std::to_string(lowest.second) + " is shared by ";
  for (const int uses : {3, 1}) {
    std::vector<std::array<int, 3>> changed = triangles;
    if (uses == 3) {
      changed.push_back(last);
    } else {
      changed.pop_back();
    }
    try {
      voxelizeSurface(points, changed, g);
      ADD_FAILURE() << "a surface not closed was voxelized";
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find("not closed (" + firstEdge + std::to_string(uses) + " triangle(s))"),
                std::string::npos)
          << e.what();
    }
  }
}

// selectLabels takes the voxels whose value rounds to a wanted label, halves
// away from zero as std::lround, for positive, zero and negative labels (it
// compares ranges instead of rounding; this checks the ranges' ends).
TEST(Volume, SelectLabelsRoundsAsLround) {
  const std::vector<float> values = {-3.5f, -2.5f, -2.4999f, -1.5f, -0.5f, -0.4999f, 0.0f, 0.4999f, 0.5f,
                                     1.4999f, 1.5f, 2.0f, 2.4999f, 2.5f, 70.5f, 71.0f, 71.4999f, 71.5f, 116.0f};
  Volume labels;
  labels.geometry = grid({static_cast<int>(values.size()), 1, 1}, Vector3::Ones(), Vector3::Zero(),
                         Matrix3::Identity());
  labels.voxels = values;
  for (const std::vector<int>& wanted : {std::vector<int>{-3}, {-2}, {-1}, {0}, {1}, {2}, {71}, {2, 71}, {5}}) {
    const Mask mask = selectLabels(labels, wanted);
    for (std::size_t v = 0; v < values.size(); ++v) {
      const long rounded = std::lround(values[v]);
      const bool expected = std::find(wanted.begin(), wanted.end(), rounded) != wanted.end();
      EXPECT_EQ(mask.voxels[v], expected ? 1 : 0) << "value " << values[v] << ", first wanted label " << wanted[0];
    }
  }
}

}  // namespace
}  // namespace dynsub
