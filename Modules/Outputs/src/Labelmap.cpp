#include "dynsub/Labelmap.h"

#include "dynsub/Voxelize.h"

namespace dynsub {

Mask labelmapOf(const TriangleSurface& surface, const ImageGeometry& grid) {
  const auto [first, size] = boundingRegion(grid, surface.points, 2.0);
  const Mask part = voxelizeSurface(surface.points, surface.triangles, grid.region(first, size));
  return pasteMask(part, grid, first);
}

}  // namespace dynsub
