#include "ItkThresholdLevelSet.h"
#include "ItkImages.h"
#include "ItkLevelSetSteps.h"

#include <chrono>
#include <cmath>
#include <stdexcept>

#include <itkThresholdSegmentationLevelSetImageFilter.h>

namespace itkbaseline {

using dynsub::itkbridge::FloatImage;
using dynsub::itkbridge::makeImage;
using ByteImage = dynsub::itkbridge::MaskImage;

ThresholdLevelSetResult thresholdLevelSet(const Geometry& grid, const std::vector<float>& voxels,
                                          const std::vector<std::uint8_t>& initialMask,
                                          const std::vector<std::array<int, 3>>& edgeVoxels,
                                          const ThresholdLevelSetOptions& options) {
  const auto started = std::chrono::steady_clock::now();
  ThresholdLevelSetResult result;
  double sum = 0.0, squares = 0.0;
  long long count = 0;
  for (std::size_t i = 0; i < initialMask.size(); ++i)
    if (initialMask[i]) sum += voxels[i], squares += double(voxels[i]) * voxels[i], ++count;
  if (count == 0) throw std::runtime_error("empty initial mask");
  const double mean = sum / count;
  const double deviation = std::sqrt(std::max(0.0, squares / count - mean * mean));
  result.lower = mean - options.window * deviation;
  result.upper = mean + options.window * deviation;
  if (options.window <= 0) {
    double darker = 0, brighter = 0;
    int darkCount = 0, brightCount = 0;
    for (const auto& v : edgeVoxels) {
      const double value = voxels[(static_cast<std::size_t>(v[2]) * grid.size[1] + v[1]) * grid.size[0] + v[0]];
      if (value < mean) darker += value, ++darkCount;
      else brighter += value, ++brightCount;
    }
    if (darkCount == 0 || brightCount == 0) throw std::runtime_error("the edge voxels are not on both sides");
    result.lower = darker / darkCount;
    result.upper = brighter / brightCount;
  }

  const auto image = makeImage<FloatImage>(grid, voxels);
  const auto initial = makeImage<ByteImage>(grid, initialMask);

  auto levelSet = itk::ThresholdSegmentationLevelSetImageFilter<FloatImage, FloatImage>::New();
  levelSet->SetInput(initialLevelSet(initial));
  levelSet->SetFeatureImage(image);
  levelSet->SetLowerThreshold(result.lower);
  levelSet->SetUpperThreshold(result.upper);
  levelSet->SetPropagationScaling(options.propagation);
  levelSet->SetCurvatureScaling(options.curvature);
  levelSet->SetMaximumRMSError(options.maximumRmsError);
  levelSet->SetNumberOfIterations(options.iterations);

  levelSet->Update();
  result.elapsedIterations = static_cast<int>(levelSet->GetElapsedIterations());
  result.mask = insideOf(levelSet->GetOutput());
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  return result;
}

}  // namespace itkbaseline
