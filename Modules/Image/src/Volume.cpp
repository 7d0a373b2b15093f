#include "dynsub/Volume.h"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <sstream>

namespace dynsub {

Vector3 ImageGeometry::toPhysical(const Vector3& index) const {
  return origin + direction * spacing.cwiseProduct(index);
}

Vector3 ImageGeometry::toIndex(const Vector3& point) const { return indexFromPhysical() * (point - origin); }

Matrix3 ImageGeometry::indexFromPhysical() const {
  return spacing.cwiseInverse().asDiagonal() * direction.inverse();
}

bool ImageGeometry::spans(const Vector3& index) const {
  for (int a = 0; a < 3; ++a)
    if (!(index[a] >= 0 && index[a] <= size[a] - 1)) return false;
  return true;
}

bool ImageGeometry::covers(const Vector3& point) const {
  const Vector3 index = toIndex(point);
  for (int a = 0; a < 3; ++a)
    if (!(index[a] >= -0.5 && index[a] <= size[a] - 0.5)) return false;
  return true;
}

namespace {

// sameGridAs's criteria besides the size, each named for differenceFrom.
bool sameSpacing(const ImageGeometry& a, const ImageGeometry& b) {
  return (a.spacing - b.spacing).norm() <= 1e-6 * a.spacing.norm();
}
bool sameDirection(const ImageGeometry& a, const ImageGeometry& b) {
  return (a.direction - b.direction).norm() <= 1e-6;
}
bool sameOrigin(const ImageGeometry& a, const ImageGeometry& b) {
  return (a.origin - b.origin).norm() <= 1e-6 * (1 + a.origin.norm());
}

}  // namespace

bool ImageGeometry::sameGridAs(const ImageGeometry& other) const {
  return size == other.size && sameSpacing(*this, other) && sameDirection(*this, other) && sameOrigin(*this, other);
}

std::string ImageGeometry::differenceFrom(const ImageGeometry& other, const std::string& otherName) const {
  if (sameGridAs(other)) return "";
  const auto vector = [](const Vector3& v) {
    std::ostringstream text;  // digits enough to show a difference sameGridAs sees
    text << std::setprecision(9) << "(" << v.x() << ", " << v.y() << ", " << v.z() << ")";
    return text.str();
  };
  const std::string where = ", where the " + otherName + "'s is ";
  if (size != other.size) {
    const auto sizeText = [](const std::array<int, 3>& n) {
      return std::to_string(n[0]) + " x " + std::to_string(n[1]) + " x " + std::to_string(n[2]);
    };
    return "its size is " + sizeText(size) + " voxels" + where + sizeText(other.size);
  }
  if (!sameSpacing(*this, other)) return "its spacing is " + vector(spacing) + " mm" + where + vector(other.spacing);
  if (!sameDirection(*this, other)) {
    double degrees = 0;
    for (int a = 0; a < 3; ++a) {
      const double cosine =
          std::clamp(direction.col(a).normalized().dot(other.direction.col(a).normalized()), -1.0, 1.0);
      degrees = std::max(degrees, std::acos(cosine) * 57.29577951308232);  // degrees per radian
    }
    std::ostringstream text;
    text << std::setprecision(3) << "its axes point other ways than the " << otherName << "'s (up to " << degrees
         << " degrees apart: a flipped, permuted or rotated copy)";
    return text.str();
  }
  return "its origin is " + vector(origin) + " mm (LPS)" + where + vector(other.origin);
}

ImageGeometry ImageGeometry::region(const std::array<int, 3>& first, const std::array<int, 3>& regionSize) const {
  ImageGeometry result = *this;
  result.size = regionSize;
  result.origin = toPhysical(Vector3(first[0], first[1], first[2]));
  return result;
}

long long Mask::count() const {
  return std::count(voxels.begin(), voxels.end(), std::uint8_t{1});
}

Mask selectLabels(const Volume& labels, const std::vector<int>& values) {
  // A voxel has label L when its value rounds to L (halves away from zero,
  // as std::lround): for L > 0 the values [L - 1/2, L + 1/2), for L < 0
  // (L - 1/2, L + 1/2], for 0 (-1/2, 1/2).
  // Compared as ranges rather than rounded voxel by voxel: lround and a
  // search of the values per voxel were a tenth of the caudate demo's
  // command with its reference (7 million voxels).
  struct Range {
    float low, high;
    bool lowIn, highIn;
  };
  std::vector<Range> ranges;
  for (int value : values) {
    const double l = value - 0.5, h = value + 0.5;
    // Exact in float for |value| < 2^23; beyond, the nearest floats (such labels are not met in practice).
    ranges.push_back({static_cast<float>(l), static_cast<float>(h), value > 0, value < 0});
  }
  Mask mask{labels.geometry, std::vector<std::uint8_t>(labels.voxels.size(), 0)};
  for (std::size_t v = 0; v < labels.voxels.size(); ++v) {
    const float f = labels.voxels[v];
    std::uint8_t inside = 0;
    for (const Range& r : ranges)
      inside |= static_cast<std::uint8_t>((r.lowIn ? f >= r.low : f > r.low) && (r.highIn ? f <= r.high : f < r.high));
    mask.voxels[v] = inside;
  }
  return mask;
}

namespace {

// The voxels of `image` (a Volume or a Mask) on an index box.
template <class Image>
Image cropImage(const Image& image, const std::array<int, 3>& first, const std::array<int, 3>& size) {
  Image result;
  result.geometry = image.geometry.region(first, size);
  result.voxels.resize(result.geometry.voxelCount());
  long long out = 0;
  for (int k = 0; k < size[2]; ++k)
    for (int j = 0; j < size[1]; ++j)
      for (int i = 0; i < size[0]; ++i)
        result.voxels[out++] = image.voxels[image.geometry.offset(first[0] + i, first[1] + j, first[2] + k)];
  return result;
}

}  // namespace

Volume cropVolume(const Volume& volume, const std::array<int, 3>& first, const std::array<int, 3>& size) {
  return cropImage(volume, first, size);
}

Mask cropMask(const Mask& mask, const std::array<int, 3>& first, const std::array<int, 3>& size) {
  return cropImage(mask, first, size);
}

std::pair<std::array<int, 3>, std::array<int, 3>> boundingRegion(const ImageGeometry& geometry,
                                                                 const MatrixX3& points, double margin) {
  Vector3 low = Vector3::Constant(1e300), high = Vector3::Constant(-1e300);
  // The margin is in mm along every axis: grow the physical box's corners.
  Vector3 lowPoint = points.colwise().minCoeff().transpose() - Vector3::Constant(margin);
  Vector3 highPoint = points.colwise().maxCoeff().transpose() + Vector3::Constant(margin);
  for (int corner = 0; corner < 8; ++corner) {
    Vector3 p;
    for (int a = 0; a < 3; ++a) p[a] = ((corner >> a) & 1) ? highPoint[a] : lowPoint[a];
    const Vector3 index = geometry.toIndex(p);
    low = low.cwiseMin(index);
    high = high.cwiseMax(index);
  }
  std::array<int, 3> first{}, size{};
  for (int a = 0; a < 3; ++a) {
    const int begin = std::clamp(static_cast<int>(std::floor(low[a])), 0, geometry.size[a] - 1);
    const int end = std::clamp(static_cast<int>(std::ceil(high[a])), begin, geometry.size[a] - 1);
    first[a] = begin;
    size[a] = end - begin + 1;
  }
  return {first, size};
}

std::pair<std::array<int, 3>, std::array<int, 3>> occupiedRegion(const ImageGeometry& g,
                                                                 const std::vector<std::uint8_t>& voxels, int margin) {
  std::array<int, 3> low{g.size[0], g.size[1], g.size[2]}, high{-1, -1, -1};
  for (int k = 0; k < g.size[2]; ++k)
    for (int j = 0; j < g.size[1]; ++j) {
      const std::uint8_t* row = voxels.data() + g.offset(0, j, k);
      const std::uint8_t* end = row + g.size[0];
      const std::uint8_t* first = std::find_if(row, end, [](std::uint8_t v) { return v != 0; });
      if (first == end) continue;
      const std::uint8_t* last = end - 1;
      while (*last == 0) --last;
      low = {std::min(low[0], static_cast<int>(first - row)), std::min(low[1], j), std::min(low[2], k)};
      high = {std::max(high[0], static_cast<int>(last - row)), std::max(high[1], j), std::max(high[2], k)};
    }
  std::array<int, 3> first{}, size{};
  if (high[0] < 0) return {first, size};
  for (int a = 0; a < 3; ++a) {
    first[a] = std::max(0, low[a] - margin);
    size[a] = std::min(g.size[a] - 1, high[a] + margin) - first[a] + 1;
  }
  return {first, size};
}

Mask pasteMask(const Mask& part, const ImageGeometry& full, const std::array<int, 3>& first) {
  Mask result{full, std::vector<std::uint8_t>(full.voxelCount(), 0)};
  const auto& n = part.geometry.size;
  long long in = 0;
  for (int k = 0; k < n[2]; ++k)
    for (int j = 0; j < n[1]; ++j)
      for (int i = 0; i < n[0]; ++i, ++in)
        if (part.voxels[in]) result.voxels[full.offset(first[0] + i, first[1] + j, first[2] + k)] = 1;
  return result;
}

}  // namespace dynsub
