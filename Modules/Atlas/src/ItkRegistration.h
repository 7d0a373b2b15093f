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

struct BSplineSettings {
  double gridSpacingMm = 20.0;   // between the control points of the cubic B-spline
  double largestShiftMm = 10.0;  // bound of each control point's displacement (L-BFGS-B's box)
  std::vector<double> levelsMm{2.0};
  int iterations = 60;            // per level, at most
  double samplingFraction = 0.2;
  int histogramBins = 32;
};

struct BSplineOutcome {
  // The B-spline's displacement d (x, y, z per voxel, i fastest) on `field`,
  // a grid over the fixed image's extent as fine as the last level: a fixed
  // point x maps to affine(x + d(x)) in the moving image. The B-spline is
  // smooth on the scale of its control points, so d is interpolated from
  // this grid to any finer one within a hundredth of a millimetre.
  Geometry field;
  std::vector<float> displacement;
  double metric = 0;
  int iterations = 0;
};

// A cubic B-spline refinement, in the fixed image's (usually a region's)
// extent, of `affine` (applied after it). Throws dynsub::Error when the
// optimizer fails.
DYNSUB_ITK_BRIDGE_API BSplineOutcome registerBSpline(const Geometry& fixedGeometry, const std::vector<float>& fixed,
                                                     const Geometry& movingGeometry, const std::vector<float>& moving,
                                                     const AffineArray& affine, const BSplineSettings& settings);

}  // namespace dynsub::itkbridge
