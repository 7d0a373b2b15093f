#pragma once
// A result's labelmap: its final surface voxelized on an image's grid.
#include "dynsub/Tessellation.h"
#include "dynsub/Volume.h"

namespace dynsub {

// The voxels of `grid` whose centres lie inside `surface` (Voxelize.h). Only
// the part of the grid the surface covers, grown by 2 mm, is voxelized (the
// surface may have left a region of interest, or the grid), then pasted onto
// the whole grid. Throws dynsub::Error for an open surface.
Mask labelmapOf(const TriangleSurface& surface, const ImageGeometry& grid);

}  // namespace dynsub
