#pragma once
// Segmenting a structure in a 3D image (TVCG 1998 §3.2, §4.3): the dynamic
// surface moves under the image force of EdgePotential.h (k times the unit
// direction towards the nearest edge, a force per unit area) and springs from
// the expert's landmarks to their nearest surface points, with multilevel
// refinement at equilibrium (the papers' 98 -> 386 control vertices).
//
// Refinement: at each level's equilibrium the fit is accepted when every
// landmark lies within `landmarkTolerance` mm of the surface; otherwise the
// control mesh is subdivided, up to `simulation.maxLevel` times. Without
// landmarks there is no misfit to measure, and the model is refined to
// maxLevel.
//
// The work is confined to a region of interest: the bounding box of the
// initial model and the landmarks, grown by `margin` mm (enough for the
// surface to reach edges beyond them); the edge potential is built there only.
// The result is the final control mesh and its limit surface; the outputs
// (Labelmap.h) voxelize that surface on the input image's full grid.
#include <array>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "dynsub/ControlMesh.h"
#include "dynsub/EdgePotential.h"
#include "dynsub/InitialModels.h"
#include "dynsub/Landmarks.h"
#include "dynsub/Simulation.h"
#include "dynsub/SliceEnds.h"
#include "dynsub/Tessellation.h"
#include "dynsub/Volume.h"

namespace dynsub {

struct SegmentOptions {
  EdgeOptions edges;
  double imageForce = 0.05;        // k, N/mm^2 of surface
  double landmarkStiffness = 10.0;  // N/mm per landmark
  double landmarkDeadZone = 0.0;    // mm: a landmark's spring pulls only beyond this (a click's error)
  double landmarkTolerance = 0.5;   // mm, largest landmark distance accepted without refining
  double inflation = 0.0;          // N/mm^2 along the normal (> 0 grows)
  // A pressure gated by appearance (N/mm^2, 0: off): k g(I) along the
  // normal, with g = 1 - |I - m| / (regionWindow s) clamped to [-1, 1], m and
  // s the median and robust spread (1.4826 MAD) of the intensities inside
  // the initial model. It grows the surface through tissue like the inside
  // and pushes it back where the intensity is unlike it.
  double regionPressure = 0.0;
  double regionWindow = 2.0;
  double margin = 8.0;             // mm around the model and the landmarks
  // Soft springs where the tissue between the clicked slices ends beyond
  // them (SliceEnds.h), for landmarks placed on slices.
  SliceEndOptions sliceEnds;
  SimulationOptions simulation = defaultSimulation();

  static SimulationOptions defaultSimulation();
};

struct StageSeconds {
  double crop = 0, potential = 0, evolution = 0;
};

struct SegmentResult {
  ControlMesh mesh;
  // The limit surface of `mesh` (the last level's tables), and its triangles,
  // 8 x 8 squares per control face (outputSegments):
  // what the labelmap, surface.vtp, the report and the figures show.
  std::shared_ptr<const LimitSurface> limit;
  TriangleSurface surface;
  std::vector<LevelSummary> levels;
  int steps = 0;
  StageSeconds seconds;
  EdgeScale edgeScale;  // the edge thresholds used
  std::vector<double> landmarkDistances;  // mm, final distance of each landmark to the surface
  std::array<int, 3> regionFirst{}, regionSize{};  // the region of interest (voxel box)
  LevelOrigin origin;  // of `mesh`: a refit from it continues its levels (Simulation.h)
  // What tells a result not to trust (segment() fills these): the volumes
  // enclosed by the initial model and by the result (mm^3), the share of the
  // result's surface outside the region of interest, where no image force
  // acts, and a warning for each of: a collapse (the result encloses less
  // than kCollapsedBelow of the initial model's volume), a cut by the
  // image's side (more than kAtImageSideAbove of the surface within a voxel
  // of it), a leak (more than kLeakedAbove of the surface left the region
  // elsewhere than at the image's side, where a wider region cannot follow).
  double initialVolume = 0, volume = 0;
  double outsideRegion = 0;  // fraction of the tessellation's points
  // Fraction of the tessellation's points within a voxel of the image's
  // side or beyond it: where the scan's field of view may cut the structure.
  double atImageSide = 0;
  // Fraction of the tessellation's points outside the region but not at
  // the image's side: the leak.
  double leakedInImage = 0;
  // With the edge potential: the share of the surface within a voxel of an
  // edge (held by the image rather than by tension and landmarks alone), and
  // each landmark's distance to the nearest edge (mm; a click beyond the
  // capture range of every edge, where the image says nothing, is warned
  // of). NaN / empty for the plain gradient potential. The edge distance is
  // no detector of mistaken clicks: on the tuning split, clicks 3 mm off the
  // boundary are no farther from the edge map than true ones
  // (Documentation/Segmentation.md).
  double surfaceOnEdges = std::numeric_limits<double>::quiet_NaN();
  std::vector<double> landmarkEdgeDistances;
  // Per point of `surface`: the distance to the nearest edge (mm), -1 outside the region
  // where it is unknown. Empty for the plain gradient potential.
  Eigen::VectorXd surfaceEdgeDistances;
  SliceEnds sliceEnds;  // what options.sliceEnds found (no springs when off)
  std::vector<std::string> warnings;
};

constexpr double kCollapsedBelow = 0.5;
constexpr double kLeakedAbove = 0.05;
// A surface with more of its points than this within a voxel of the image's
// side is warned of as cut by the field of view: a structure well inside
// the scan keeps every point away from it.
constexpr double kAtImageSideAbove = 0.01;

// Throws LandmarkError ("landmark 2 of 36 ('F-2') at (x, y, z) mm LPS lies
// outside the image") for the first landmark `grid` does not cover.
void requireLandmarksInside(const ImageGeometry& grid, const std::vector<Landmark>& landmarks);

// The image side of a segmentation: the region of interest cropped from the
// image and its edge field (EdgePotential.h), with the time each took.
// segment() builds one per call; an interactive refit keeps it and reuses it
// while the model and the landmarks stay inside.
class SegmentationRegion {
 public:
  // The bounding box of the initial model's limit surface and the landmarks,
  // grown by options.margin mm; the landmarks set the edge thresholds. The
  // box also holds `alsoCover` (e.g. soft springs), which set nothing. Throws
  // as segment() does when a landmark or the model lies outside the image.
  SegmentationRegion(const Volume& image, const std::vector<Landmark>& landmarks, const ControlMesh& initial,
                     const SegmentOptions& options, const std::vector<Landmark>& alsoCover = {});

  // Whether every point lies inside the region's grid (a refit beyond it
  // needs a new region: the edge directions are zero outside).
  bool covers(const MatrixX3& points) const;
  bool covers(const Vector3& point) const;

  const EdgeField& edgeField() const { return *edgeField_; }
  const Volume& image() const { return image_; }  // the image cropped to the region
  const ImageGeometry& wholeImage() const { return wholeImage_; }  // the grid of the image it was cropped from
  // The region as asked for along image axis `axis`, in mm along its
  // direction: the box's points projected, grown by the margin. The grid's
  // whole voxels reach up to a voxel beyond it.
  std::pair<double, double> spanAlong(int axis) const { return span_[axis]; }
  const std::array<int, 3>& first() const { return first_; }  // voxel box in the image
  const std::array<int, 3>& size() const { return size_; }
  double cropSeconds() const { return cropSeconds_; }
  double potentialSeconds() const { return potentialSeconds_; }

 private:
  std::array<int, 3> first_{}, size_{};
  std::array<std::pair<double, double>, 3> span_;
  ImageGeometry geometry_, wholeImage_;
  Volume image_;
  double cropSeconds_ = 0, potentialSeconds_ = 0;
  std::unique_ptr<const EdgeField> edgeField_;
};

// Whether a model's limit surface (2 x 2 samples per face, as segment()
// checks an initial model) lies within the grid's voxels.
bool limitSurfaceInside(const ControlMesh& mesh, const ImageGeometry& grid);

// The papers' cube placed inside the landmarks' PCA ellipsoid (`fraction`
// of its semi-axes, by default half). Throws dynsub::Error for fewer than 4
// landmarks or flat ones (LandmarkError for landmarks on one plane).
ControlMesh initialFromLandmarks(const std::vector<Landmark>& landmarks, double fraction = 0.5);

// Throws dynsub::Error when the initial model lies outside the image or for
// impossible options, LandmarkError when a landmark lies outside the image or
// the landmarks are on no edge (EdgePotential.h). extraForces (not owned) act besides the
// image, landmark and inflation forces, e.g. an interactive pull
// (ForceModel.h); the progress callback may throw to stop the evolution.
// `resume`, if given, is an earlier result of the same inputs: the region,
// the ends and the collapse check still come from `initial`, but the
// evolution resumes from that result's surface and levels, so that extra
// forces move it only where they act (a structure pushed back from its
// neighbours keeps the rest of its equilibrium). A result whose surface left
// the region is not resumed from: the evolution starts from `initial`.
SegmentResult segment(const Volume& image, const std::vector<Landmark>& landmarks, const ControlMesh& initial,
                      const SegmentOptions& options, const ProgressCallback& progress = nullptr,
                      const std::vector<ForceModel*>& extraForces = {}, const SegmentResult* resume = nullptr);

// The evolution alone, in a region built for these options (no labelmap; the
// result's landmarkDistances and levels are filled): what an interactive
// refit runs. `initial` may be an earlier result's mesh, with its `origin`.
// `pressure` (not owned), if given, acts with the image force (ForceModel.h's
// FieldForceModel). segment()'s springs and pressure at the ends beyond the
// clicked slices are not part of this: an interactive refit runs without them.
SegmentResult evolveInRegion(const SegmentationRegion& region, const std::vector<Landmark>& landmarks,
                             const ControlMesh& initial, const LevelOrigin& origin, const SegmentOptions& options,
                             const ProgressCallback& progress = nullptr,
                             const std::vector<ForceModel*>& extraForces = {},
                             const PressureField* pressure = nullptr);

void checkSegmentOptions(const SegmentOptions& options);

// Distance (mm) from each landmark (row of `landmarkPoints`) to the exact limit
// surface at `controlPoints`: the misfit the refinement rule and the report use.
std::vector<double> distancesToSurface(const LimitSurface& surface, const MatrixX3& controlPoints,
                                       const MatrixX3& landmarkPoints);

}  // namespace dynsub
