#pragma once
// The image filters DynSub takes from ITK, on the project's own types: the
// rest of the project samples fields built with these and never sees ITK.
#include <vector>

#include "dynsub/Types.h"
#include "dynsub/Volume.h"

namespace dynsub {

// The gradient (LPS axes, per mm) of the image smoothed by a Gaussian of
// sigma mm, with Deriche's recursive filters: one vector per voxel, in the
// voxels' order.
std::vector<Vector3> smoothedGradient(const Volume& image, double sigma);

// The Euclidean distance (mm, by the grid's spacing) from every voxel centre
// to the nearest voxel of `mask`, 0 on it, in the voxels' order; exact
// (ITK's Maurer transform).
std::vector<float> distanceTo(const Mask& mask);

}  // namespace dynsub
