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
//  3. Hysteresis: candidates at or above the high threshold are edges, and so
//     are candidates at or above the low threshold 26-connected to an edge.
//     Both thresholds are fractions of a reference gradient magnitude, so they
//     do not depend on the scanner's intensity scale (EdgeReference):
//     - with landmarks, the median over them of the strongest magnitude within
//       `landmarkReach` mm (1) of each: the strength of the boundary the
//       expert marked. Edges are kept when they are about as strong as that
//       boundary (0.75 / 1.0 of it), so the weaker edges inside a textured
//       structure (the cerebellum's folia, the hippocampus' layers) do not
//       hold the surface in, and a faint structure (the caudate against the
//       internal capsule) keeps its faint edges;
//       If that median is under 1 % of the image's 99th-percentile magnitude
//       the landmarks are not on an edge, and LandmarksOffEdges is thrown
//       rather than thresholds set from flat tissue;
//     - without landmarks, the image's 99th-percentile magnitude (0.10 / 0.25
//       of it).
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
#include <vector>

#include "dynsub/Error.h"
#include "dynsub/Volume.h"

namespace dynsub {

enum class EdgeMethod { MongaDeriche, GradientMagnitude };

// What the hysteresis thresholds are fractions of (step 3 above).
enum class EdgeReference {
  Landmarks,  // the landmarks' median edge magnitude; the image's when no landmarks are given
  Image,      // the 99th-percentile gradient magnitude in the image
};

struct Hysteresis {
  double low, high;  // fractions of the reference magnitude, low <= high
};

struct EdgeOptions {
  EdgeMethod method = EdgeMethod::MongaDeriche;
  double sigma = 1.0;  // mm, Gaussian smoothing of the derivative filters
  EdgeReference reference = EdgeReference::Landmarks;
  Hysteresis ofLandmarks{0.75, 1.0};   // used when the reference is the landmarks' median
  double landmarkReach = 1.0;          // mm: a landmark's edge is the strongest magnitude this close
  Hysteresis ofImage{0.10, 0.25};      // used when it is the image's 99th percentile
  double captureRange = 6.0;           // mm
};

// The thresholds an edge map was built with, for reports.
struct EdgeScale {
  EdgeReference reference = EdgeReference::Image;  // the one used
  double magnitude = 0;                            // the reference magnitude, intensity per mm
  Hysteresis fractions{0, 0};
};

// Landmarks given to set the edge thresholds lie where the image has no edge (step 3).
class LandmarksOffEdges : public LandmarkError {
 public:
  using LandmarkError::LandmarkError;
};

// The gradient's magnitude per voxel, as an image on `geometry`.
Volume magnitudeOf(const ImageGeometry& geometry, const std::vector<Vector3>& gradient);

// The strongest value of a gradient magnitude image within `radius` mm of a
// point, and the voxel it is at (offset -1 when no voxel is that near): the
// height of the edge an expert meant when clicking next to it. Along an axis
// whose voxels are longer than twice the radius (thick slices), a voxel is
// as near as its slab: a click between two slices sees both.
struct StrongestVoxel {
  double magnitude = 0;
  long long offset = -1;
};
StrongestVoxel strongestVoxelNear(const Volume& magnitude, const Vector3& point, double radius);

// Throws dynsub::Error for non-finite or impossible options.
void checkEdgeOptions(const EdgeOptions& options);

// The edge map of the image's grid, the distance to it, and the unit
// directions grad(P) / |grad(P)| of eq. 28's force (LPS); EdgeForce.h makes
// them a force.
class EdgeField {
 public:
  // `landmarks` (N x 3, mm) are points on the wanted boundary; they set the
  // edge thresholds when options.reference is Landmarks (see above); throws
  // LandmarksOffEdges when they are not on an edge.
  EdgeField(const Volume& image, const EdgeOptions& options, const MatrixX3& landmarks = MatrixX3());

  // N points in mm -> N unit (or zero) vectors, trilinearly interpolated.
  MatrixX3 sample(const MatrixX3& points) const;
  // How fast the sampled unit vectors can change, per mm: they can reverse
  // (+1 to -1) between neighbouring voxels (across an edge two voxels thick,
  // or the ridge midway between two edges), so 2 / (smallest spacing).
  double slopeBound() const;

  const Mask& edges() const { return edges_; }  // MongaDeriche only (else empty)
  // Distance (mm) from a point to the nearest edge voxel, trilinear between
  // voxel centres (MongaDeriche only; infinity outside the image, without an
  // edge map, or when it holds no edge).
  double edgeDistance(const Vector3& point) const;
  const EdgeScale& scale() const { return scale_; }  // MongaDeriche only

 private:
  ImageGeometry geometry_;
  EdgeScale scale_;
  // The unit vectors, x, y and z side by side per voxel: sample() reads a
  // voxel's three components from one cache line.
  std::vector<float> vectors_;
  Mask edges_;
  Volume edgeDistance_;  // MongaDeriche only: step 4's distance d
  bool hasEdges_ = false;
};

}  // namespace dynsub
