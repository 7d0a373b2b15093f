#include "RobustStatistics.h"

#include <cmath>
#include <utility>
#include <vector>

#include "dynsub/LimitSurface.h"
#include "dynsub/Percentile.h"
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

// The 99th percentile of the gradient magnitude (central differences, per
// mm) over every second voxel of the grid in each direction: how fast the
// intensity under a moving surface can change, bar the steepest voxels.
double steepGradient(const Volume& image) {
  const ImageGeometry& g = image.geometry;
  std::vector<double> magnitudes;
  for (int k = 1; k + 1 < g.size[2]; k += 2)
    for (int j = 1; j + 1 < g.size[1]; j += 2)
      for (int i = 1; i + 1 < g.size[0]; i += 2) {
        const double dx = (image.voxels[g.offset(i + 1, j, k)] - image.voxels[g.offset(i - 1, j, k)]) / (2 * g.spacing(0));
        const double dy = (image.voxels[g.offset(i, j + 1, k)] - image.voxels[g.offset(i, j - 1, k)]) / (2 * g.spacing(1));
        const double dz = (image.voxels[g.offset(i, j, k + 1)] - image.voxels[g.offset(i, j, k - 1)]) / (2 * g.spacing(2));
        magnitudes.push_back(std::sqrt(dx * dx + dy * dy + dz * dz));
      }
  return percentile(std::move(magnitudes), 0.99);
}

}  // namespace dynsub
