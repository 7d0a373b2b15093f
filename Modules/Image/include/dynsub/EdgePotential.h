#pragma once
// The image force of TVCG 1998 §3.2 (eq. 28): f = k grad(P) / |grad(P)|, with P
// a potential built from a 3D Monga-Deriche edge map of the smoothed image.
//
// How P is built (EdgeMethod::MongaDeriche):
//  1. Gradient of the image smoothed by a Gaussian of `sigma` mm, with Deriche's
//     recursive filters (itk::GradientRecursiveGaussianImageFilter: the
//     smoothing and the derivative in one recursive pass per axis, in mm).
//  2. 3D non-maximum suppression: a voxel is an edge candidate when its
//     gradient magnitude is at least the magnitude one voxel-length ahead and
//     behind along its own gradient direction (trilinear interpolation).
//  3. Hysteresis: candidates at or above `highThreshold` are edges, and so are
//     candidates at or above `lowThreshold` 26-connected to an edge. Both are
//     fractions of the 99th percentile of the gradient magnitude in the image,
//     so they do not depend on the scanner's intensity scale.
//  4. P = -d, with d the Euclidean distance (mm, the image's spacing) to the
//     nearest edge voxel (itk::SignedMaurerDistanceMapImageFilter), so that
//     grad(P) / |grad(P)| is the unit vector towards the nearest edge. It is
//     taken by central differences: at an edge voxel they cancel, so edges are
//     equilibria, and the trilinearly interpolated force grows linearly over
//     the first voxel around an edge (a spring-like well, not a sign flip).
//     Beyond `captureRange` mm from every edge the force is zero.
//
// EdgeMethod::GradientMagnitude is the plain alternative it is measured
// against: P = |grad(G_sigma * I)|, the force its normalized gradient.
//
// The field is sampled at any point in mm (trilinear interpolation of the
// three components); outside the image it is zero.
#include <string>

#include "dynsub/Volume.h"

namespace dynsub {

enum class EdgeMethod { MongaDeriche, GradientMagnitude };

struct EdgeOptions {
  EdgeMethod method = EdgeMethod::MongaDeriche;
  double sigma = 1.0;           // mm, Gaussian smoothing of the derivative filters
  double lowThreshold = 0.10;   // hysteresis, fraction of the 99th-percentile gradient magnitude
  double highThreshold = 0.25;
  double captureRange = 6.0;    // mm
};

// Throws dynsub::Error for non-finite or impossible options.
void checkEdgeOptions(const EdgeOptions& options);

// Unit force directions (LPS) on the image's grid, and the edge map they come from.
class DirectionField {
 public:
  DirectionField(const Volume& image, const EdgeOptions& options);

  // N points in mm -> N unit (or zero) vectors, trilinearly interpolated.
  Matrix3X sample(const Matrix3X& points) const;
  // How fast the sampled unit vectors can change, per mm: they can reverse
  // (+1 to -1) between neighbouring voxels (across an edge two voxels thick,
  // or the ridge midway between two edges), so 2 / (smallest spacing).
  double slopeBound() const;

  const Mask& edges() const { return edges_; }  // MongaDeriche only (else empty)

 private:
  ImageGeometry geometry_;
  Volume components_[3];
  Mask edges_;
};

}  // namespace dynsub
