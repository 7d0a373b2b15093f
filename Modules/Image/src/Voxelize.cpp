#include "dynsub/Voxelize.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include "dynsub/Error.h"

namespace dynsub {

Mask voxelizeSurface(const MatrixX3& points, const std::vector<std::array<int, 3>>& triangles,
                     const ImageGeometry& grid) {
  // Every edge must be shared by two triangles. The edges bucketed by their
  // lower point (a counting sort), each bucket's higher points sorted and
  // counted in runs: the first edge not shared by two is the lowest pair.
  // A std::map of the edges was three quarters of the voxelization
  // (49 000 triangles for a segmentation's output), sorting them all a third.
  const Eigen::Index pointCount = points.rows();
  std::vector<int> bucketStart(static_cast<std::size_t>(pointCount) + 1, 0);
  for (const auto& t : triangles)
    for (int e = 0; e < 3; ++e) {
      const int a = t[e], b = t[(e + 1) % 3];
      if (a < 0 || b < 0 || a >= pointCount || b >= pointCount)
        throw Error("cannot voxelize: a triangle names point " + std::to_string(std::max(a, b)) + " of " +
                    std::to_string(pointCount));
      ++bucketStart[std::min(a, b) + 1];
    }
  for (Eigen::Index p = 0; p < pointCount; ++p) bucketStart[p + 1] += bucketStart[p];
  std::vector<int> higher(3 * triangles.size());
  std::vector<int> filled(bucketStart.begin(), bucketStart.end() - 1);
  for (const auto& t : triangles)
    for (int e = 0; e < 3; ++e) {
      const int a = t[e], b = t[(e + 1) % 3];
      higher[filled[std::min(a, b)]++] = std::max(a, b);
    }
  for (Eigen::Index p = 0; p < pointCount; ++p) {
    const auto begin = higher.begin() + bucketStart[p], end = higher.begin() + bucketStart[p + 1];
    std::sort(begin, end);
    for (auto first = begin, last = begin; first != end; first = last) {
      while (last != end && *last == *first) ++last;
      if (last - first != 2)
        throw Error("cannot voxelize: the surface is not closed (edge " + std::to_string(p) + "-" +
                    std::to_string(*first) + " is shared by " + std::to_string(last - first) + " triangle(s))");
    }
  }

  Mask mask{grid, std::vector<std::uint8_t>(grid.voxelCount(), 0)};
  const int rowsJ = grid.size[1], rowsK = grid.size[2];
  // Where each row crosses the surface, and which way: +1 or -1 by the sign of
  // the triangle's normal along the row.
  struct Crossing {
    double at;
    int sense;
    bool operator<(const Crossing& other) const { return at < other.at; }
  };
  std::vector<std::vector<Crossing>> crossings(static_cast<std::size_t>(rowsJ) * rowsK);
  // The row through voxel centres (j, k) is shifted by this much, see the header.
  const double shiftJ = 1.0e-6, shiftK = 1.7e-6;

  const MatrixX3 index = (points.rowwise() - grid.origin.transpose()) * grid.indexFromPhysical().transpose();

  for (const auto& t : triangles) {
    const Vector3 a = index.row(t[0]), b = index.row(t[1]), c = index.row(t[2]);
    const int j0 = std::max(0, static_cast<int>(std::ceil(std::min({a[1], b[1], c[1]}) - shiftJ)));
    const int j1 = std::min(rowsJ - 1, static_cast<int>(std::floor(std::max({a[1], b[1], c[1]}) - shiftJ)));
    const int k0 = std::max(0, static_cast<int>(std::ceil(std::min({a[2], b[2], c[2]}) - shiftK)));
    const int k1 = std::min(rowsK - 1, static_cast<int>(std::floor(std::max({a[2], b[2], c[2]}) - shiftK)));
    // Barycentric coordinates of the row's (j, k) in the triangle's projection.
    const double det = (b[1] - a[1]) * (c[2] - a[2]) - (c[1] - a[1]) * (b[2] - a[2]);
    if (det == 0) continue;  // parallel to the rows: crossed by none
    for (int k = k0; k <= k1; ++k)
      for (int j = j0; j <= j1; ++j) {
        const double y = j + shiftJ - a[1], z = k + shiftK - a[2];
        const double s = (y * (c[2] - a[2]) - (c[1] - a[1]) * z) / det;
        const double r = ((b[1] - a[1]) * z - y * (b[2] - a[2])) / det;
        if (s < 0 || r < 0 || s + r > 1) continue;
        crossings[static_cast<std::size_t>(k) * rowsJ + j].push_back(
            {a[0] + s * (b[0] - a[0]) + r * (c[0] - a[0]), det > 0 ? 1 : -1});
      }
  }

  for (int k = 0; k < rowsK; ++k)
    for (int j = 0; j < rowsJ; ++j) {
      auto& row = crossings[static_cast<std::size_t>(k) * rowsJ + j];
      // A closed surface winds around each point a whole number of times, so a
      // row's senses sum to 0; any other sum means a crossing was lost at a
      // tangency or counted twice on a shared edge, and the row is left out
      // rather than filled wrongly.
      int total = 0;
      for (const Crossing& c : row) total += c.sense;
      if (total != 0) continue;
      std::sort(row.begin(), row.end());
      // Inside where the surface winds around the voxel's centre (the nonzero rule, Voxelize.h).
      int winding = 0;
      for (std::size_t c = 0; c + 1 < row.size(); ++c) {
        winding += row[c].sense;
        if (winding == 0) continue;
        const int first = std::max(0, static_cast<int>(std::ceil(row[c].at)));
        const int last = std::min(grid.size[0] - 1, static_cast<int>(std::floor(row[c + 1].at)));
        for (int i = first; i <= last; ++i) mask.voxels[grid.offset(i, j, k)] = 1;
      }
    }
  return mask;
}

}  // namespace dynsub
