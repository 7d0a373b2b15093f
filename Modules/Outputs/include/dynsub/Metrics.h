#pragma once
// Agreement between two masks on the same grid, as segmentation papers and
// ITK-SNAP/3D Slicer's tools report it:
//  - dice = 2|A∩B| / (|A|+|B|), jaccard = |A∩B| / |A∪B|;
//  - volumeDifferencePercent = 100 (|A| - |B|) / |B| (B the reference);
//  - surface distances between the boundary voxels of A and of B (a voxel of
//    the mask with a 6-neighbour outside it, or on the image border), in mm
//    between voxel centres (the grid's spacing and direction):
//    meanSurfaceDistance averages the distances from every boundary voxel of A
//    to B's boundary and of B to A's; hd95 is the 95th percentile of that same
//    pooled set; hausdorff its maximum.
#include "dynsub/Volume.h"

namespace dynsub {

struct OverlapMetrics {
  double dice = 0;
  double jaccard = 0;
  double volumeDifferencePercent = 0;
  double meanSurfaceDistance = 0;  // mm
  double hd95 = 0;                 // mm
  double hausdorff = 0;            // mm
  long long voxelsA = 0, voxelsB = 0;
  double volumeA = 0, volumeB = 0;  // mm^3
};

// a: the segmentation, b: the reference. Throws dynsub::Error if the grids
// differ or either mask is empty.
OverlapMetrics compareMasks(const Mask& a, const Mask& b);

}  // namespace dynsub
