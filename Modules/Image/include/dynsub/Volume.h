#pragma once
// 3D images as plain buffers with their geometry, so that the rest of DynSub
// never includes ITK. Physical space is LPS mm, as in ITK and DICOM:
//   x_mm = origin + direction * diag(spacing) * index,
// with index (i, j, k) of a voxel centre and i varying fastest in memory.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "dynsub/Types.h"

namespace dynsub {


struct ImageGeometry {
  std::array<int, 3> size{0, 0, 0};
  Vector3 spacing = Vector3::Ones();  // mm
  Vector3 origin = Vector3::Zero();   // mm, centre of voxel (0, 0, 0)
  Matrix3 direction = Matrix3::Identity();  // columns: the i, j, k axes in LPS

  long long voxelCount() const { return static_cast<long long>(size[0]) * size[1] * size[2]; }
  long long offset(int i, int j, int k) const {
    return i + static_cast<long long>(size[0]) * (j + static_cast<long long>(size[1]) * k);
  }
  // The voxel (i, j, k) at a linear offset: offset()'s inverse.
  std::array<int, 3> voxelAt(long long offset) const {
    const long long plane = static_cast<long long>(size[0]) * size[1];
    return {static_cast<int>(offset % size[0]), static_cast<int>(offset % plane / size[0]),
            static_cast<int>(offset / plane)};
  }
  bool contains(int i, int j, int k) const {
    return i >= 0 && j >= 0 && k >= 0 && i < size[0] && j < size[1] && k < size[2];
  }
  // Continuous index <-> physical point (mm).
  Vector3 toPhysical(const Vector3& index) const;
  Vector3 toIndex(const Vector3& point) const;
  // Whether a physical point lies in one of the grid's voxels (continuous
  // index within -0.5 .. size - 0.5 on every axis).
  bool covers(const Vector3& point) const;
  // Whether a continuous index lies between the first and the last voxel
  // centres on every axis (0 .. size - 1): where trilinear interpolation
  // needs no clamping, i.e. where the image is known rather than repeated.
  bool spans(const Vector3& index) const;
  // The linear part of toIndex, index = indexFromPhysical() * (point - origin),
  // for loops over many points (it holds a 3 x 3 inverse).
  Matrix3 indexFromPhysical() const;
  // Same size, and origin, spacing and direction equal to within 1e-6 (relative
  // for origin and spacing): the two images' voxels are the same places.
  bool sameGridAs(const ImageGeometry& other) const;
  // How this grid differs from `other`, called `otherName`, in words (the
  // first difference: "its size is 91 x 109 x 91 voxels, where the image's
  // is 181 x 217 x 181"); empty when sameGridAs.
  std::string differenceFrom(const ImageGeometry& other, const std::string& otherName) const;
  // The same grid on the index box [first, first + size).
  ImageGeometry region(const std::array<int, 3>& first, const std::array<int, 3>& regionSize) const;
};

// Where a trilinear interpolation at a continuous index reads (clamped to
// the image): the eight corners' voxel offsets and weights, corner c at
// (base + (c & 1, c >> 1 & 1, c >> 2 & 1)). Images of one geometry share
// them, so several images are sampled at a point for the price of one
// lookup (the edge field's three components).
struct Trilinear {
  long long offset[8];
  double weight[8];
};
// Inline: the edge field samples it at every quadrature point of every step.
inline Trilinear trilinearAt(const ImageGeometry& geometry, const Vector3& index) {
  const auto& n = geometry.size;
  int base[3];
  double t[3];
  for (int a = 0; a < 3; ++a) {
    const double x = std::clamp(index[a], 0.0, static_cast<double>(n[a] - 1));
    base[a] = std::min(static_cast<int>(std::floor(x)), std::max(n[a] - 2, 0));
    t[a] = x - base[a];
  }
  Trilinear corners;
  for (int corner = 0; corner < 8; ++corner) {
    double weight = 1;
    int at[3];
    for (int a = 0; a < 3; ++a) {
      const int high = (corner >> a) & 1;
      weight *= high ? t[a] : 1 - t[a];
      at[a] = std::min(base[a] + high, n[a] - 1);
    }
    corners.weight[corner] = weight;
    corners.offset[corner] = geometry.offset(at[0], at[1], at[2]);
  }
  return corners;
}

// An intensity image (any pixel type read as float).
struct Volume {
  ImageGeometry geometry;
  std::vector<float> voxels;

  float at(int i, int j, int k) const { return voxels[geometry.offset(i, j, k)]; }
  // Trilinear interpolation at a continuous index; clamped to the image.
  double interpolate(const Vector3& index) const { return interpolate(trilinearAt(geometry, index)); }
  // The same from a lookup made on this image's geometry.
  double interpolate(const Trilinear& corners) const {
    double sum = 0;
    for (int c = 0; c < 8; ++c) {
      if (corners.weight[c] != 0) sum += corners.weight[c] * voxels[corners.offset[c]];
    }
    return sum;
  }
};

// A binary image: 1 inside the structure, 0 outside.
struct Mask {
  ImageGeometry geometry;
  std::vector<std::uint8_t> voxels;

  long long count() const;
};

// The voxels of `labels` whose value is one of `values`.
Mask selectLabels(const Volume& labels, const std::vector<int>& values);

// The sub-image on an index box (clamped to the image).
Volume cropVolume(const Volume& volume, const std::array<int, 3>& first, const std::array<int, 3>& size);
Mask cropMask(const Mask& mask, const std::array<int, 3>& first, const std::array<int, 3>& size);

// The smallest index box, grown by `margin` mm on every side and clamped to the
// image, that contains the given physical points. Returns {first, size}.
std::pair<std::array<int, 3>, std::array<int, 3>> boundingRegion(const ImageGeometry& geometry,
                                                                 const MatrixX3& points, double margin);

// The smallest index box holding every non-zero voxel of `voxels` (on
// `geometry`'s grid, in its order), grown by `margin` voxels on every side and
// clamped to the grid. Returns {first, size}; size zero when there is none.
std::pair<std::array<int, 3>, std::array<int, 3>> occupiedRegion(const ImageGeometry& geometry,
                                                                 const std::vector<std::uint8_t>& voxels, int margin);

// A mask on `region` (a sub-grid of `full`, as from ImageGeometry::region)
// pasted into an empty mask on the full grid.
Mask pasteMask(const Mask& part, const ImageGeometry& full, const std::array<int, 3>& first);

}  // namespace dynsub
