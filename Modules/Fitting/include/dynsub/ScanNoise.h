#pragma once
// What a scan's points say about their own accuracy, before any fit.
//
// Each point is compared with the surface its nearest neighbours describe: a
// quadric z = q(x, y) fitted by least squares in the frame of the
// neighbours' principal axes (z the least), the point itself left out. Its
// offset from that quadric, divided by the prediction's spread
// sqrt(1 + leverage), is the point's standardized residual t.
//  - The noise: sigma from the lower quartile of |t| over the points (the
//    quartile divided by Phi^-1(5/8) = 0.3186, what it is for Gaussian
//    noise), the robust standard deviation of a point about the surface. A
//    quadric follows the surface's curvature, so on a densely sampled smooth
//    surface t is the noise alone; near a crease or a corner, where
//    neighbours from both sides bend the quadric, |t| is larger. The lower
//    quartile holds while up to three quarters of the points are such: on a
//    clean scan of a cube, most of whose points have neighbours across an
//    edge, the median of |t| reads 0.14 % of its diagonal as noise and the
//    quartile none, while the two agree within 0.5-3 % on noisy scans of
//    smooth shapes (CGAL's bear and kitten, 0.1 and 0.3 % noise).
//  - Outliers: points whose |t| exceeds kOutlierFactor times both sigma and
//    their neighbourhood's own scale (1.4826 median |r| of the neighbours'
//    residuals from the same quadric), and half the points' usual spacing.
//    The neighbourhood's own scale keeps points where the quadric cannot
//    follow the surface (a crease, a sparse scan) from being called
//    outliers; a point scattered off the surface stands out against
//    neighbours that lie on it. Points too far off for their neighbours to
//    be a patch of the surface are caught by isolation instead
//    (kIsolationFactor).
//  - Shape, not noise: a quadric follows the surface only over a
//    neighbourhood where the scan samples its curvature densely. Where it
//    does not (a few hundred points on a shape with handles), the residuals
//    are the surface's own bending, and they grow with the neighbourhood
//    (a quadric's misfit with its radius cubed), while noise does not
//    depend on how many neighbours are fitted. The scatter is measured with
//    kNoiseNeighbours and with kNoiseNeighboursFew; when the first exceeds
//    the second kShapeGrowth-fold, sigma is 0: the scan is fitted as clean
//    data, since what its scatter measures is detail the fit must follow.
// The quadric is fitted twice: the second fit leaves out the neighbours the
// first left farther than 3 of its scales, so that an outlier among the
// neighbours neither tilts the frame nor bends the quadric.
//
// Outliers drop out of a fit's springs (ShapeRecovery.h), the way robust ICP
// trims its worst pairs, but decided from the data alone: a coarse surface
// far from a genuine detail (a tail, an ear) does not make the detail's
// points look like outliers, which trimming by residual would.
#include <vector>

#include "dynsub/Types.h"

namespace dynsub {

struct ScanNoise {
  double sigma = 0.0;  // mm; 0 when the scatter is the surface's shape (above)
  // The robust sigma of the standardized residuals (above), mm, with
  // kNoiseNeighbours and with kNoiseNeighboursFew neighbours.
  double scatter = 0.0, scatterFew = 0.0;
  std::vector<int> outliers;  // indices into the points, ascending
};

// Neighbours per point for the quadrics: 6 coefficients, with room left to
// measure the residuals' spread.
constexpr int kNoiseNeighbours = 20;
// The smaller neighbourhood the scatter is compared with: 6 coefficients
// and as many residuals left.
constexpr int kNoiseNeighboursFew = 12;
// Scatter that grows more than this from kNoiseNeighboursFew to
// kNoiseNeighbours neighbours is shape, not noise. On the synthetic tuning
// clouds (Tools/tuning_clouds.py) the noisy peanut's grows 1.06-fold (0.99
// on its dense version) and the clean clouds' 1.5-4.4-fold. Nearer the
// clean end, since a clean scan read as noisy has a sigma too small to
// matter unless it is sparse, while noise read as shape is chased to the
// last level.
constexpr double kShapeGrowth = 1.5;
// |t| beyond this many scales is an outlier: a Gaussian point exceeds 4
// standard deviations about once in 16 000.
constexpr double kOutlierFactor = 4.0;
// A point whose mean distance to its neighbours is this many times theirs
// (the median over them), or the median over all points, is isolated: an
// outlier too far off the surface for its neighbours to be a patch of it.
// On the clean scans and clouds the project fits (the synthetic tuning
// clouds, CGAL's bear, kitten and eight) no point reaches 1.8 times the
// median over all points.
constexpr double kIsolationFactor = 3.0;

// Exact copies of a point count once, and are all outliers when it is one;
// with kNoiseNeighbours or fewer distinct points, no noise and no outliers.
// Throws dynsub::Error when there are fewer than kNoiseNeighbours + 1 points.
ScanNoise estimateScanNoise(const MatrixX3& points);

// The `count` nearest other points of each point (#points x count indices,
// nearest first). count < #points.
Eigen::MatrixXi nearestNeighbours(const MatrixX3& points, int count);

// `points` without the rows `drop` (ascending).
MatrixX3 withoutRows(const MatrixX3& points, const std::vector<int>& drop);

}  // namespace dynsub
