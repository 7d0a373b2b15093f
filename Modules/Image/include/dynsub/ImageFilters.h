#pragma once
// The image filters DynSub takes from ITK, on the project's own types: the
// rest of the project samples fields built with these and never sees ITK;
// and the distance transform, DynSub's own.
#include <vector>

#include "dynsub/Types.h"
#include "dynsub/Volume.h"

namespace dynsub {

// The gradient (LPS axes, per mm) of the image smoothed by a Gaussian of
// sigma mm, with Deriche's recursive filters: one vector per voxel, in the
// voxels' order.
std::vector<Vector3> smoothedGradient(const Volume& image, double sigma);

// The same gradient on the index box [first, first + size) of `image` alone
// (the box inside the image), in the box's voxel order: separable sampled
// Gaussians to 4 sigma, from the image's voxels within 4 sigma of the box
// (repeated beyond the image's faces, as the recursive filters' boundary
// does). Its cost is the box's and not the image's: for the gradient near a
// few points. It agrees with smoothedGradient to within 1.5 % of the
// gradient's largest magnitude (SmoothedGradientUnitTest, on Colin27).
std::vector<Vector3> smoothedGradientIn(const Volume& image, double sigma, const std::array<int, 3>& first,
                                        const std::array<int, 3>& size);

// The image smoothed by a Gaussian of sigma mm (Deriche's recursive filters).
Volume gaussianSmoothed(const Volume& image, double sigma);

// The Euclidean distance (mm, by the grid's spacing) from every voxel centre
// to the nearest voxel of `mask`, 0 on it, in the voxels' order; exact (the
// separable transform of Felzenszwalb and Huttenlocher, one pass per axis);
// infinity everywhere for an empty mask. It equals ITK's Maurer transform to
// the bit on grids whose squared distances floats hold exactly (1 mm, 0.5
// mm: DistanceUnitTests), elsewhere within a float's rounding. It is
// DynSub's own because ITK's took a third of a seed click's command.
std::vector<float> distanceTo(const Mask& mask);

}  // namespace dynsub
