#include "RobustStatistics.h"

#include "dynsub/LimitSurface.h"
#include "dynsub/Tessellation.h"
#include "dynsub/Voxelize.h"

namespace dynsub {

std::optional<RobustStatistics> insideIntensities(const Volume& image, const ControlMesh& model) {
  const TriangleSurface s = tessellate(LimitSurface(model), model.points(), 4);
  const auto [first, size] = boundingRegion(image.geometry, s.points, 1.0);
  const Volume box = cropVolume(image, first, size);
  const Mask inside = voxelizeSurface(s.points, s.triangles, box.geometry);
  std::vector<double> values;
  for (std::size_t i = 0; i < inside.voxels.size(); ++i)
    if (inside.voxels[i]) values.push_back(box.voxels[i]);
  if (values.empty()) return std::nullopt;
  return robustStatistics(std::move(values));
}

}  // namespace dynsub
