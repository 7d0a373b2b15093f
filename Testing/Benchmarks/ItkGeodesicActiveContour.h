#pragma once
// ITK's geodesic active contour (Caselles et al.), the level-set segmentation
// of ITK's own filters, as the baseline DynSub is compared with. Plain arrays
// only: ITK's bundled Eigen cannot share a translation unit with DynSub's
// (see Modules/Image/src/ItkBridge.h).
#include <array>
#include <cstdint>
#include <vector>

#include "ItkBridge.h"

namespace itkbaseline {

using dynsub::itkbridge::Geometry;

struct GacOptions {
  double sigma = 1.0;          // mm, gradient-magnitude smoothing
  double propagation = 1.0;    // balloon term (> 0 grows)
  double curvature = 1.0;
  double advection = 1.0;
  double maximumRmsError = 0.02;
  int iterations = 800;
  int diffusionIterations = 5;  // curvature anisotropic diffusion before the gradient
};

struct GacResult {
  std::vector<std::uint8_t> mask;  // 1 inside the final contour
  double alpha = 0, beta = 0;      // of the sigmoid speed image
  int elapsedIterations = 0;
  double seconds = 0;              // whole pipeline: diffusion, speed image, distance, evolution
};

// Speed image: sigmoid of the gradient magnitude, its edge and inside levels
// (alpha = -(edge - inside) / 6, beta = (edge + inside) / 2, as the ITK
// Software Guide recommends) read from the image: `edge` the mean gradient
// magnitude at `edgeVoxels` (the landmarks), `inside` its mean inside the
// initial mask. The initial level set is the signed distance to the initial
// mask's boundary.
GacResult geodesicActiveContour(const Geometry& grid, const std::vector<float>& image,
                                const std::vector<std::uint8_t>& initialMask,
                                const std::vector<std::array<int, 3>>& edgeVoxels, const GacOptions& options);

}  // namespace itkbaseline
