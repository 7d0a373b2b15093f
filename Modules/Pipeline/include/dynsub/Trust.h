#pragma once
// When a segmentation should not be trusted. A result rests on what the user
// gave or chose: boundary clicks, one click inside (SeedGrowth.h), or the
// atlas's structure carried to the image (Atlas.h). The measures compare the
// result with that evidence, and the flags are thresholds on them, chosen on
// the evaluation's tuning subjects and measured on its test subjects
// (Documentation/Segmentation.md, "What the report says about trust").
#include <limits>
#include <string>
#include <vector>

#include "dynsub/Landmarks.h"
#include "dynsub/Tessellation.h"

namespace dynsub {

struct TrustEvidence {
  std::vector<Vector3> clicks;  // the user's boundary clicks (may be empty)
  // The clicks' slices: their normal (zero when the clicks are not on
  // slices) and how near along it two clicks share a slice (mm).
  Vector3 sliceNormal = Vector3::Zero();
  double onSlice = 0;
  std::vector<Vector3> outline;       // the atlas prior's points on the carried label's boundary (may be empty)
  double volume = 0;                  // mm^3: the carried label's (0 without an atlas)
  double initialVolume = 0;           // mm^3: the initial model's (0 when unknown)
  std::vector<double> clicksToAtlas;  // mm: each click's distance to the carried label's boundary
  bool oneClick = false;              // a start from one click inside with nothing else: no clicks, no atlas
  double march = 0;                   // mm: the longest the slice-end march carried past the clicked slices
  double outsideRegion = 0;           // the share of the result outside the region of interest
  double atImageSide = 0;             // the share within a voxel of the image's side or beyond it
  double leakedInImage = 0;           // the share outside the region away from the image's side
  // mm: how far the atlas's structure was moved so that the click inside
  // (--inside) lies in it; NaN without such a click.
  double insideShift = std::numeric_limits<double>::quiet_NaN();
};

struct TrustMeasures {
  static constexpr double kNone = std::numeric_limits<double>::quiet_NaN();
  // The result's volume over the carried label's or, with clicks alone, over
  // the volume their slices outline: each clicked slice's convex hull of its
  // clicks, the areas joined slice to slice by the trapezoid rule (what the
  // result encloses between the outermost clicked slices, if it follows the
  // clicks; the parts beyond them add to the result's).
  double volumeRatio = kNone;
  // The result's volume over the initial model's. The clicks outline no
  // volume when no two slices hold three clicks each (four clicks, or clicks
  // off slices), but a surface that shrank to a fraction of where it started
  // has collapsed whatever started it.
  double initialRatio = kNone;
  double outlineDistance = kNone;       // mm: 90th percentile of the prior's points' distance to the result
  double clicksToAtlas = kNone;         // mm: 90th percentile of evidence.clicksToAtlas
  double farthestFromEvidence = kNone;  // mm: the result's point farthest from every click and prior point
  double marchShare = kNone;            // the march over the span between the outermost clicked slices
  double insideShift = kNone;           // mm: evidence.insideShift
  double outsideRegion = 0;
  double atImageSide = 0;
  double leakedInImage = 0;
};

// The thresholds, set on the tuning subjects of both generated groups
// (synthesized 401-404, single-scan 1-5 and 201-202: 614 runs, every
// protocol; Documentation/Segmentation.md), with a margin beyond the good
// results there: their lowest volume ratio was 0.81, the clicks' largest
// distance to the atlas 4.2 mm, the atlas's outline's 3.5 mm (the cerebellum).
constexpr double kTrustSmallBelow = 0.7;        // volumeRatio
constexpr double kTrustAtlasClicksApart = 6.0;  // mm, clicksToAtlas
constexpr double kTrustMovedFromAtlas = 4.5;    // mm, outlineDistance
// A click inside the structure, near its boundary, moves the atlas's structure
// a voxel or two, where the registration left it that far off; twice the
// most seen on the tuning subjects (Documentation/Segmentation.md) is a
// click elsewhere.
constexpr double kTrustMovedToClick = 4.0;  // mm, insideShift (flagged beyond it)

struct TrustFlag {
  // A stable key: one_click, collapsed, small, atlas_clicks_apart,
  // moved_from_atlas, moved_to_click, cut_by_image_side, leaked.
  std::string name;
  std::string message;  // what it means, and what to do
};

TrustMeasures measureTrust(const TriangleSurface& result, double resultVolume, const TrustEvidence& evidence);
std::vector<TrustFlag> trustFlags(const TrustMeasures& measures, const TrustEvidence& evidence);

}  // namespace dynsub
