#include "dynsub/ImageFilters.h"

#include "BridgeGeometry.h"

namespace dynsub {

std::vector<Vector3> smoothedGradient(const Volume& image, double sigma) {
  const std::vector<float> raw =
      itkbridge::functions().recursiveGaussianGradient(toBridge(image.geometry), image.voxels, sigma);
  std::vector<Vector3> gradient(image.voxels.size());
  for (std::size_t v = 0; v < gradient.size(); ++v) gradient[v] = Vector3(raw[3 * v], raw[3 * v + 1], raw[3 * v + 2]);
  return gradient;
}

std::vector<float> distanceTo(const Mask& mask) {
  return itkbridge::functions().distanceMap(toBridge(mask.geometry), mask.voxels);
}

}  // namespace dynsub
