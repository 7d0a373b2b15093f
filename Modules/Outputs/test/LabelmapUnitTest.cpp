#include "dynsub/Labelmap.h"

#include <gtest/gtest.h>

#include "TestGrids.h"
#include "dynsub/LimitSurface.h"
#include "dynsub/StandardMeshes.h"
#include "dynsub/Voxelize.h"

namespace dynsub {
namespace {

// The cube's limit surface scaled to about a 20 mm ball around (3, -2, 5).
TriangleSurface ball() {
  ControlMesh cube = makeCube98();
  cube.setPoints((cube.points() * 20.0).rowwise() + Vector3(3, -2, 5).transpose());
  return tessellate(LimitSurface(cube), cube.points(), kOutputSegments);
}

// Voxelizing only the part of the grid the surface covers changes nothing:
// every voxel equals the whole grid's voxelization (exact, not a tolerance).
TEST(Labelmap, EqualsTheWholeGridsVoxelization) {
  const TriangleSurface surface = ball();
  const ImageGeometry g = grid({80, 70, 60}, Vector3(0.9, 1.0, 1.2), Vector3(-30, -35, -30), skewDirection());
  const Mask labelmap = labelmapOf(surface, g);
  const Mask whole = voxelizeSurface(surface.points, surface.triangles, g);
  ASSERT_GT(whole.count(), 1000);
  EXPECT_EQ(labelmap.voxels, whole.voxels);
  EXPECT_TRUE(labelmap.geometry.sameGridAs(g));
}

// A surface that reaches beyond the grid is labelled where the grid has voxels.
TEST(Labelmap, ASurfacePartlyOutsideTheGridIsCutAtItsEdge) {
  const TriangleSurface surface = ball();
  const ImageGeometry g = grid({40, 70, 60}, Vector3(1, 1, 1), Vector3(3, -35, -30), Matrix3::Identity());
  const Mask labelmap = labelmapOf(surface, g);
  EXPECT_EQ(labelmap.voxels, voxelizeSurface(surface.points, surface.triangles, g).voxels);
  EXPECT_GT(labelmap.count(), 1000);
}

}  // namespace
}  // namespace dynsub
