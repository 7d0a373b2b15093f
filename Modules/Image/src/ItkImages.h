#pragma once
// Private to the Image module (and the benchmark that compares DynSub with
// ITK's own filters): ITK images made from the ITK libraries' plain buffers
// and back. ITK headers only, never with DynSub's Eigen (see ItkBridge.h).
#include <algorithm>
#include <vector>

#include <itkImage.h>

#include "ItkBridge.h"

namespace dynsub::itkbridge {

using FloatImage = itk::Image<float, 3>;
using MaskImage = itk::Image<unsigned char, 3>;

// A copy of `voxels` (i fastest) on `g`.
template <typename Image, typename Pixel>
typename Image::Pointer makeImage(const Geometry& g, const std::vector<Pixel>& voxels) {
  auto image = Image::New();
  typename Image::RegionType region;
  typename Image::SpacingType spacing;
  typename Image::PointType origin;
  typename Image::DirectionType direction;
  for (int a = 0; a < 3; ++a) {
    region.SetSize(a, g.size[a]);
    spacing[a] = g.spacing[a];
    origin[a] = g.origin[a];
    for (int b = 0; b < 3; ++b) direction(a, b) = g.direction[3 * a + b];
  }
  image->SetRegions(region);
  image->SetSpacing(spacing);
  image->SetOrigin(origin);
  image->SetDirection(direction);
  image->Allocate();
  std::copy(voxels.begin(), voxels.end(), image->GetBufferPointer());
  return image;
}

inline Geometry geometryOf(const FloatImage* image) {
  Geometry g;
  for (int a = 0; a < 3; ++a) {
    g.size[a] = static_cast<int>(image->GetLargestPossibleRegion().GetSize()[a]);
    g.spacing[a] = image->GetSpacing()[a];
    g.origin[a] = image->GetOrigin()[a];
    for (int b = 0; b < 3; ++b) g.direction[3 * a + b] = image->GetDirection()(a, b);
  }
  return g;
}

inline long long countOf(const Geometry& g) { return static_cast<long long>(g.size[0]) * g.size[1] * g.size[2]; }

}  // namespace dynsub::itkbridge
