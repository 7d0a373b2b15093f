#pragma once
// Expert-like landmark sets made from a reference labelmap, for measuring how
// a segmentation holds up under the ways real users click (Evaluation.h).
//
// An expert clicks on a few parallel slices (sagittal, coronal or axial: the
// reference's voxel axes i, j, k), on the structure's boundary, and usually
// leaves its ends unclicked. A protocol says how:
//  - `slices` slices spread evenly over a `coverage` fraction of the
//    structure's extent along the axis (drawn per seed from [coverageLow,
//    coverageHigh]), the covered part placed at random but leaving both
//    ends unclicked (each end keeps 25-75 % of the part left out);
//  - on each, `pointsPerSlice` boundary points (midpoints between a voxel
//    of the structure and an in-slice 4-neighbour outside it), spread by
//    farthest-point sampling from a random first point;
//  - each click moved in the slice's plane by a normal error of `scatter` mm
//    per in-plane axis (a steady hand is about 0.4 mm);
//  - `mistakes` of the clicks moved `mistakeDistance` mm off the boundary,
//    in or out across it, in the slice's plane.
// With `seedOnly`, the protocol is one click inside the structure and no
// landmarks: with `seedDepth` 1, the voxel deepest inside it (farthest from
// its boundary, nearest the centroid among ties); below 1, a voxel drawn
// from `seed` among those at least that fraction of the deepest depth
// inside, as a user clicks somewhere well inside, not at its very middle.
//
// Everything is drawn from `seed`: the same protocol and seed give the same
// clicks wherever the same C++ standard library runs (its distributions and
// shuffle are not specified bit for bit across libraries).
#include <string>
#include <vector>

#include "dynsub/Landmarks.h"
#include "dynsub/Volume.h"

namespace dynsub {

struct ClickProtocol {
  std::string name;
  int axis = 1;  // 0 sagittal (i), 1 coronal (j), 2 axial (k)
  int slices = 6;
  int pointsPerSlice = 6;
  double coverageLow = 0.6, coverageHigh = 0.8;  // fraction of the extent the slices span
  double scatter = 0.4;                          // mm, per in-plane axis
  int mistakes = 0;
  double mistakeDistance = 3.0;  // mm
  bool seedOnly = false;
  double seedDepth = 1.0;  // seed-only: the least depth of the click, a fraction of the deepest (0, 1]
};

// Throws dynsub::Error for impossible protocols, an empty reference or a
// reference without enough boundary on a chosen slice.
std::vector<Landmark> expertClicks(const Mask& reference, const ClickProtocol& protocol, unsigned seed);

// The one click of a seed-only protocol: LPS mm, inside the reference
// (`depth`: the protocol's seedDepth).
Vector3 seedClick(const Mask& reference, double depth = 1.0, unsigned seed = 0);

void checkClickProtocol(const ClickProtocol& protocol);

}  // namespace dynsub
