#include "ItkDeformableSimplexMesh.h"
#include "ItkImages.h"

#include <chrono>
#include <stdexcept>

#include <itkCovariantVector.h>
#include <itkDeformableSimplexMesh3DBalloonForceFilter.h>
#include <itkDeformableSimplexMesh3DFilter.h>
#include <itkGradientMagnitudeRecursiveGaussianImageFilter.h>
#include <itkGradientRecursiveGaussianImageFilter.h>
#include <itkMesh.h>
#include <itkMinimumMaximumImageCalculator.h>
#include <itkRescaleIntensityImageFilter.h>
#include <itkSimplexMesh.h>
#include <itkSimplexMeshToTriangleMeshFilter.h>
#include <itkTriangleCell.h>
#include <itkTriangleMeshToSimplexMeshFilter.h>

namespace itkbaseline {

using dynsub::itkbridge::FloatImage;
using dynsub::itkbridge::makeImage;

SimplexResult deformableSimplexMesh(const Geometry& grid, const std::vector<float>& voxels,
                                    const std::vector<std::array<double, 3>>& points,
                                    const std::vector<std::array<int, 3>>& triangles, const SimplexOptions& options) {
  // Float throughout: the triangle filter builds its output with float coordinates.
  using TriangleMesh = itk::Mesh<float, 3>;
  using SimplexMesh = itk::SimplexMesh<float, 3>;
  using Deform = itk::DeformableSimplexMesh3DFilter<SimplexMesh, SimplexMesh>;
  using GradientImage = Deform::GradientImageType;
  const auto started = std::chrono::steady_clock::now();

  // The image in index space: the filter's only frame.
  Geometry indexGrid = grid;
  indexGrid.spacing = {1.0, 1.0, 1.0};
  indexGrid.origin = {0.0, 0.0, 0.0};
  indexGrid.direction = {1, 0, 0, 0, 1, 0, 0, 0, 1};
  auto magnitude = itk::GradientMagnitudeRecursiveGaussianImageFilter<FloatImage, FloatImage>::New();
  magnitude->SetInput(makeImage<FloatImage>(indexGrid, voxels));
  magnitude->SetSigma(options.sigma);
  auto rescale = itk::RescaleIntensityImageFilter<FloatImage, FloatImage>::New();
  rescale->SetInput(magnitude->GetOutput());
  rescale->SetOutputMinimum(0.0);
  rescale->SetOutputMaximum(1.0);
  auto gradient = itk::GradientRecursiveGaussianImageFilter<FloatImage, GradientImage>::New();
  gradient->SetInput(rescale->GetOutput());
  gradient->SetSigma(options.sigma);
  gradient->Update();

  auto mesh = TriangleMesh::New();
  for (std::size_t i = 0; i < points.size(); ++i) {
    TriangleMesh::PointType p;
    for (int a = 0; a < 3; ++a) p[a] = points[i][a];
    mesh->SetPoint(i, p);
  }
  using CellAutoPointer = TriangleMesh::CellType::CellAutoPointer;
  using Triangle = itk::TriangleCell<TriangleMesh::CellType>;
  for (std::size_t t = 0; t < triangles.size(); ++t) {
    CellAutoPointer cell;
    cell.TakeOwnership(new Triangle);
    for (int c = 0; c < 3; ++c) cell->SetPointId(c, triangles[t][c]);
    mesh->SetCell(t, cell);
  }
  auto toSimplex = itk::TriangleMeshToSimplexMeshFilter<TriangleMesh, SimplexMesh>::New();
  toSimplex->SetInput(mesh);

  // With a balloon (kappa != 0) the subclass that adds it along the normals.
  Deform::Pointer deform;
  if (options.kappa != 0) {
    auto balloon = itk::DeformableSimplexMesh3DBalloonForceFilter<SimplexMesh, SimplexMesh>::New();
    balloon->SetKappa(options.kappa);
    deform = balloon;
  } else {
    deform = Deform::New();
  }
  deform->SetInput(toSimplex->GetOutput());
  deform->SetGradient(gradient->GetOutput());
  deform->SetAlpha(options.alpha);
  deform->SetBeta(options.beta);
  deform->SetGamma(options.gamma);
  deform->SetDamping(options.damping);
  deform->SetRigidity(options.rigidity);
  deform->SetIterations(options.iterations);

  auto toTriangles = itk::SimplexMeshToTriangleMeshFilter<SimplexMesh, TriangleMesh>::New();
  toTriangles->SetInput(deform->GetOutput());
  toTriangles->Update();
  const TriangleMesh* out = toTriangles->GetOutput();

  SimplexResult result;
  for (auto p = out->GetPoints()->Begin(); p != out->GetPoints()->End(); ++p) {
    if (p.Index() != result.points.size()) throw std::runtime_error("the simplex mesh's points are not numbered 0..n-1");
    result.points.push_back({p.Value()[0], p.Value()[1], p.Value()[2]});
  }
  for (auto c = out->GetCells()->Begin(); c != out->GetCells()->End(); ++c) {
    const auto* cell = c.Value();
    if (cell->GetNumberOfPoints() != 3) continue;
    const auto* ids = cell->GetPointIds();
    result.triangles.push_back({static_cast<int>(ids[0]), static_cast<int>(ids[1]), static_cast<int>(ids[2])});
  }
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  return result;
}

}  // namespace itkbaseline
