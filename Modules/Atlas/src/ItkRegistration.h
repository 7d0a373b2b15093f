#pragma once
// Private to the Atlas module: ITK's registration behind plain arrays, in a
// shared library of its own, for the reason Image's ItkBridge.h gives (ITK
// bundles an Eigen that must not meet DynSub's). Points are LPS mm; a
// transform maps a point of the fixed image (the subject) to the moving one
// (the atlas's template), as ITK's registration defines it.
#include <array>
#include <vector>

#include "ItkBridge.h"

namespace dynsub::itkbridge {

// y = A x + t, stored row-major as [A | t] (3 x 4).
using AffineArray = std::array<double, 12>;

struct AffineSettings {
  // Voxel sizes (mm) of the pyramid's levels, coarse to fine: each image is
  // smoothed and shrunk to about these before it is compared.
  std::vector<double> levelsMm{4.0, 2.0};
  int iterations = 200;           // per level, at most
  double samplingFraction = 0.2;  // of the fixed image's voxels, drawn at random (seeded)
  int histogramBins = 32;
};

struct AffineOutcome {
  AffineArray transform{};
  double metric = 0;  // Mattes mutual information at the end (negative: lower is better)
  int iterations = 0;  // over all levels
};

// A rigid start from the images' centres of mass, then an affine transform
// maximizing Mattes mutual information over a smoothed pyramid. Throws
// dynsub::Error when the optimizer fails.
DYNSUB_ITK_BRIDGE_API AffineOutcome registerAffine(const Geometry& fixedGeometry, const std::vector<float>& fixed,
                                                   const Geometry& movingGeometry, const std::vector<float>& moving,
                                                   const AffineSettings& settings);

struct DeformableSettings {
  double levelMm = 2.0;        // the displacement field's voxel size
  int iterations = 50;         // at most
  // The Gaussian smoothing of each step's update and of the total field
  // (sigma, mm): what keeps the field smooth and one to one.
  double updateSigmaMm = 4.0;
  double totalSigmaMm = 2.0;
  int histogramBins = 32;
};

struct DeformableOutcome {
  // The displacement d (x, y, z per voxel, i fastest) on `field`, a grid
  // over the fixed image's extent with levelMm voxels: a fixed point x maps
  // to affine(x + d(x)) in the moving image, d interpolated trilinearly.
  Geometry field;
  std::vector<float> displacement;
  double metric = 0;
  int iterations = 0;
};

// A dense displacement field refining `affine` (applied after it) over the
// fixed image (usually a region), by gradient descent on Mattes mutual
// information with the field smoothed at every step, as ANTs' Gaussian
// displacement field does: each voxel's displacement depends on its
// neighbourhood only, so a step costs the same whatever the region's size.
// Throws dynsub::Error when the optimizer fails.
DYNSUB_ITK_BRIDGE_API DeformableOutcome registerDeformable(const Geometry& fixedGeometry,
                                                           const std::vector<float>& fixed,
                                                           const Geometry& movingGeometry,
                                                           const std::vector<float>& moving,
                                                           const AffineArray& affine,
                                                           const DeformableSettings& settings);

}  // namespace dynsub::itkbridge
