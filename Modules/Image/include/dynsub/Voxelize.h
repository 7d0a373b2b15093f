#pragma once
// A closed triangle surface (in mm) turned into a mask on an image grid: a
// voxel is inside when its centre is. Each row of voxels along the grid's
// first axis is a line in physical space; the surface's crossings of that line
// (computed in continuous index space, where the line is axis-aligned, so any
// direction matrix and spacing are handled exactly) are sorted, each with the
// way the surface faces there, and the voxels around which the surface winds
// any number of times but 0 are set (the nonzero rule). Where a surface that
// passes through itself overlaps itself it winds twice, inside too, which the
// even-odd rule would leave out; for a consistently oriented surface that
// does not cross itself (a model's), the two rules agree. The rows are offset by
// 1e-6 voxel so that no row passes exactly through a triangle edge or vertex.
#include <array>
#include <vector>

#include "dynsub/Volume.h"

namespace dynsub {

// Throws dynsub::Error if the surface is not closed (an edge not shared by
// exactly two triangles) or a triangle names a missing point.
Mask voxelizeSurface(const MatrixX3& points, const std::vector<std::array<int, 3>>& triangles,
                     const ImageGeometry& grid);

}  // namespace dynsub
