#pragma once
// One click inside a structure, and no landmarks: the region the click's
// tissue fills, as a start for segment() (what ITK-SNAP's bubbles and its
// intensity thresholds do, without asking the user for the thresholds).
//
//  1. Appearance: the median m and the robust spread s (1.4826 x the median
//     absolute deviation) of the intensities within `statsRadius` mm of the
//     click. s is at least 1 % of the image's robust range (1st to 99th
//     percentile near the click), so a flat image still has a window.
//  2. Growth: the voxels 6-connected to the click's voxel whose intensity
//     lies within m +- window s, no farther than `reach` mm from the click
//     along any axis.
//  3. Opening by a ball of `opening` mm: the grown voxels deeper than that
//     (by exact Euclidean distance, distanceTo in Volume.h) that stay connected to the click, grown
//     back by the same distance inside the grown region. This cuts the thin
//     bridges through which like tissue joins the structure to its
//     neighbours.
//  4. Holes (voxels no path from the region's box border reaches) are filled.
//
// Leak guard: a region that reaches the edge of its box has leaked into
// like tissue around the structure. It is grown again with a narrower
// window (at most 2.5 spreads), then with openings 1 and 2 mm wider, and the
// first region that stays inside is kept. When none does, the last is
// returned with `touchesReach` set, for the caller to warn of.
//
// The result's boundary (midpoints between its voxels and their outside
// 6-neighbours) is where segment() starts from: its points serve as soft
// landmarks and set the edge thresholds (Segmentation.h).
#include <array>
#include <string>
#include <vector>

#include "dynsub/Landmarks.h"
#include "dynsub/Volume.h"

namespace dynsub {

// The defaults were chosen on the evaluation plan's tuning split
// (Documentation/Segmentation.md).
struct SeedOptions {
  double statsRadius = 2.5;  // mm
  double window = 4.0;       // robust spreads either side of the median
  double reach = 60.0;       // mm from the click, per axis
  double opening = 1.5;      // mm, ball radius (0: none)
  int boundaryPoints = 60;   // at most this many boundary points are kept
  double stiffness = 2.0;    // N/mm: the boundary points' springs when they are the only landmarks
};

struct SeedRegion {
  Vector3 click = Vector3::Zero();  // LPS mm
  Mask mask;  // on a sub-grid of the image around the click (ImageGeometry::region)
  std::array<int, 3> first{};  // the sub-grid's first voxel in the image
  double median = 0, spread = 0;  // the appearance learned at the click
  double low = 0, high = 0;       // the intensity window grown through
  double window = 0, opening = 0;  // what the leak guard settled on
  long long grownVoxels = 0;      // before the opening
  // Boundary points (LPS mm), spread over the region's surface by
  // farthest-point sampling from the one nearest the click.
  std::vector<Landmark> boundary;
  bool touchesReach = false;  // the region reached the edge of its box: it has probably leaked
  // The region grown and opened the same way through a window 0.8 times as
  // wide (mm^3). A region many times larger than that sits where a little
  // more window let it through into like tissue (seedWarnings).
  double narrowerWindowVolume = 0;
};

void checkSeedOptions(const SeedOptions& options);

// The region's volume (mm^3).
double regionVolume(const SeedRegion& region);

// What a region grown from a click should be trusted for: a warning when it
// leaked (touchesReach), one when it is more than kLeakGrowth times the
// region a window 0.8 times as wide gives (its size hangs on the window:
// when that narrower region is itself no small one, it leaked without
// reaching the edge of its box, the last fifth of the window joining a
// neighbour to it; otherwise it may be part of a textured structure),
// and one when it holds less than a ball of 5 mm radius (524 mm^3), too
// little for the surface started from it not to shrink (the guard narrows
// the window until the growth stays inside its reach, which in textured
// tissue can leave a few voxels).
std::vector<std::string> seedWarnings(const SeedRegion& region);
// The leak signs above: the region reached its box, or the last fifth of its
// window grew a region of at least kSmallSeedRegion more than kLeakGrowth times.
bool probablyLeaked(const SeedRegion& region);

constexpr double kSmallSeedRegion = 524.0;  // mm^3
// Chosen on the evaluation plan's tuning split (Documentation/Segmentation.md,
// "One seed click"): its regions that did not leak grew at most 2.0 times
// over the last fifth of their window, those that leaked 3.7-42 times.
constexpr double kLeakGrowth = 3.0;

// Throws dynsub::Error for a click outside the image or impossible options,
// and when every opening leaves nothing at the click (a click on a structure
// thinner than twice the opening, or on its edge).
SeedRegion growFromSeed(const Volume& image, const Vector3& click, const SeedOptions& options = {});

}  // namespace dynsub
