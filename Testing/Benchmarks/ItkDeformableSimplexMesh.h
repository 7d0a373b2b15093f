#pragma once
// ITK's deformable simplex mesh (Delingette's simplex meshes;
// itk::DeformableSimplexMesh3DFilter), the deformable-surface model of ITK's
// own filters, as a second baseline beside the geodesic active contour.
// Plain arrays only (see ItkGeodesicActiveContour.h).
//
// The filter works in index space only (it refuses an image whose origin is
// not 0 or whose spacing is not 1, and reads the mesh's points as voxel
// indices), so the mesh goes in and comes out in continuous voxel indices of
// `grid`; the caller maps them to millimetres.
#include <array>
#include <vector>

#include "ItkBridge.h"

namespace itkbaseline {

using dynsub::itkbridge::Geometry;

struct SimplexOptions {
  double sigma = 1.0;  // voxels, gradient-magnitude smoothing
  double alpha = 0.2;  // internal (smoothness) force
  double beta = 0.1;   // external (image) force
  double gamma = 0.05;
  double damping = 0.65;
  unsigned rigidity = 1;
  int iterations = 300;
  double kappa = 0;  // balloon along the normals (itk::DeformableSimplexMesh3DBalloonForceFilter); 0: none
};

struct SimplexResult {
  std::vector<std::array<double, 3>> points;  // continuous voxel indices of `grid`
  std::vector<std::array<int, 3>> triangles;
  double seconds = 0;  // speed image, mesh conversion and deformation
};

// External force: the gradient of the gradient magnitude (its maxima are the
// edges), the magnitude first scaled to [0, 1] by its largest value so that
// beta does not depend on the scanner's intensity scale. The triangle mesh
// (closed) becomes its dual simplex mesh, deforms, and comes back as triangles.
SimplexResult deformableSimplexMesh(const Geometry& grid, const std::vector<float>& image,
                                    const std::vector<std::array<double, 3>>& points,
                                    const std::vector<std::array<int, 3>>& triangles, const SimplexOptions& options);

}  // namespace itkbaseline
