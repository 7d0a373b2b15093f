#pragma once
// The steps ITK's level-set baselines share: the initial level set from a
// mask, and the mask inside a final level set. ITK types only; include in
// the Itk*.cpp files alone (see ItkGeodesicActiveContour.h).
#include <cstdint>
#include <vector>

#include <itkBinaryThresholdImageFilter.h>
#include <itkSignedMaurerDistanceMapImageFilter.h>

#include "ItkImages.h"

namespace itkbaseline {

// The signed distance (mm, negative inside) to the mask's boundary.
inline dynsub::itkbridge::FloatImage::Pointer initialLevelSet(const dynsub::itkbridge::MaskImage* mask) {
  using namespace dynsub::itkbridge;
  auto distance = itk::SignedMaurerDistanceMapImageFilter<MaskImage, FloatImage>::New();
  distance->SetInput(mask);
  distance->SetInsideIsPositive(false);
  distance->SetSquaredDistance(false);
  distance->SetUseImageSpacing(true);
  distance->Update();
  return distance->GetOutput();
}

// 1 where the level set is <= 0 (inside the front), as a plain buffer.
inline std::vector<std::uint8_t> insideOf(const dynsub::itkbridge::FloatImage* levelSet) {
  using namespace dynsub::itkbridge;
  auto threshold = itk::BinaryThresholdImageFilter<FloatImage, MaskImage>::New();
  threshold->SetInput(levelSet);
  threshold->SetLowerThreshold(-1e30);
  threshold->SetUpperThreshold(0.0);
  threshold->SetInsideValue(1);
  threshold->SetOutsideValue(0);
  threshold->Update();
  const MaskImage* out = threshold->GetOutput();
  return {out->GetBufferPointer(), out->GetBufferPointer() + out->GetBufferedRegion().GetNumberOfPixels()};
}

}  // namespace itkbaseline
