#pragma once
// What the tissue looks like on either side of the boundary the expert
// clicked, and a pressure that uses it where no click holds the surface.
//
// ClickAppearance: each click on a slice, with the centroid of its slice's
// clicks as "inward", gives intensity samples `offset` and 2 `offset` mm
// inside and outside it (trilinear). The two samples become kernel densities
// p_in and p_out, and an intensity I scores (p_in - p_out) / (p_in + p_out):
// +1 where it looks like the inside only, -1 like the outside only, 0 where
// both or neither. Learning the outside as well as the inside is what keeps
// a pressure from growing into tissue that is merely close in intensity (the
// caudate's neighbour, the internal capsule, is 10-15 units brighter).
//
// EndPressure: beyond the outermost clicked slices (along the slices' axis;
// nothing within the clicked span, where the clicks hold the surface), a
// pressure k score(I) along the normal. The surface grows through
// inside-like tissue and is pushed back from outside-like tissue until the
// two balance, at the boundary the clicks taught. Its slope, k times the
// score's largest slope per intensity times the region's 99th-percentile
// gradient magnitude, joins the edge force's in the integrator's stabilizer
// (Integrator.h): without it the pressure flips sign across the boundary
// from step to step, and a level can run to its step limit instead of
// settling.
#include <limits>
#include <optional>
#include <vector>

#include "dynsub/Forces.h"
#include "dynsub/Landmarks.h"
#include "dynsub/Volume.h"

namespace dynsub {

class ClickAppearance {
 public:
  // Clicks on slices along image axis `axis` of `image`'s grid (a slice's
  // clicks share their index along it to a quarter voxel); a click on a slice
  // with fewer than 3 clicks, or at its centroid, gives no samples. None when
  // either side has fewer than 8 samples inside the image.
  static std::optional<ClickAppearance> learn(const Volume& image, const std::vector<Landmark>& landmarks, int axis,
                                              double offset = 1.5);

  double score(double intensity) const;  // in [-1, 1]
  double largestSlope() const { return largestSlope_; }  // of the score, per intensity unit
  int insideSamples() const { return insideSamples_; }
  int outsideSamples() const { return outsideSamples_; }
  // The total variation distance between the two densities: 0 when they
  // are the same, 1 when they do not overlap.
  double separation() const { return separation_; }

 private:
  ClickAppearance() = default;  // only learn() makes one
  std::vector<double> table_;  // scores on a uniform grid of intensities
  double first_ = 0, step_ = 1;
  double largestSlope_ = 0, separation_ = 0;
  int insideSamples_ = 0, outsideSamples_ = 0;
};

class EndPressure final : public PressureField {
 public:
  // Where the pressure acts beyond one end of the clicked span: within
  // `radius` of the line along the axis through `centre`, the end slice's
  // clicks' centroid (radius: its farthest click). A structure's unclicked
  // end is taken to be no wider than its last clicked section: without this
  // bound the pressure can grow an end sideways into like tissue beside it
  // (a cerebellum's lateral ends into the temporal lobes). Nor farther
  // than `reach` mm beyond the end slice: where like tissue goes on past the
  // structure's end (below a thalamus), the pressure stops only there, and a
  // bound in mm stops it at the same place on 1 mm and 3 mm slices, where the
  // region's whole voxels would reach up to a voxel farther.
  struct End {
    Vector3 centre = Vector3::Zero();
    double radius = 0;
    double reach = std::numeric_limits<double>::infinity();
  };
  // `region`: the image the pressure samples (not copied: it must outlive
  // this); the clicked span is that of `landmarks` along `axis`; `before`
  // is its end towards lower indices along the axis, `after` the other
  // (none: no pressure beyond it).
  EndPressure(const Volume& region, ClickAppearance appearance, const std::vector<Landmark>& landmarks, int axis,
              double strength, std::optional<End> before, std::optional<End> after);
  Eigen::VectorXd pressuresAt(const MatrixX3& points) const override;
  double slopeBound() const override { return slopeBound_; }

 private:
  const Volume& region_;
  ClickAppearance appearance_;
  Matrix3 toIndex_;
  Vector3 along_;
  double first_ = 0, last_ = 0;  // the clicked span, mm along `along_`
  std::optional<End> before_, after_;
  double strength_ = 0, slopeBound_ = 0;
};

}  // namespace dynsub
