#include "ItkGeodesicActiveContour.h"
#include "ItkImages.h"
#include "ItkLevelSetSteps.h"

#include <chrono>
#include <stdexcept>

#include <itkCurvatureAnisotropicDiffusionImageFilter.h>
#include <itkGeodesicActiveContourLevelSetImageFilter.h>
#include <itkGradientMagnitudeRecursiveGaussianImageFilter.h>
#include <itkSigmoidImageFilter.h>

namespace itkbaseline {

using dynsub::itkbridge::FloatImage;
using dynsub::itkbridge::makeImage;
using ByteImage = dynsub::itkbridge::MaskImage;

GacResult geodesicActiveContour(const Geometry& grid, const std::vector<float>& voxels,
                                const std::vector<std::uint8_t>& initialMask,
                                const std::vector<std::array<int, 3>>& edgeVoxels, const GacOptions& options) {
  const auto started = std::chrono::steady_clock::now();
  const auto image = makeImage<FloatImage>(grid, voxels);
  const auto initial = makeImage<ByteImage>(grid, initialMask);

  auto diffusion = itk::CurvatureAnisotropicDiffusionImageFilter<FloatImage, FloatImage>::New();
  diffusion->SetInput(image);
  diffusion->SetNumberOfIterations(options.diffusionIterations);
  diffusion->SetTimeStep(0.0625);  // stable for 3D
  diffusion->SetConductanceParameter(9.0);
  auto gradient = itk::GradientMagnitudeRecursiveGaussianImageFilter<FloatImage, FloatImage>::New();
  gradient->SetInput(diffusion->GetOutput());
  gradient->SetSigma(options.sigma);
  gradient->Update();
  const FloatImage* magnitude = gradient->GetOutput();

  GacResult result;
  double edge = 0.0, inside = 0.0;
  long long insideCount = 0;
  for (const auto& v : edgeVoxels) edge += magnitude->GetPixel({{v[0], v[1], v[2]}});
  edge /= std::max<std::size_t>(edgeVoxels.size(), 1);
  for (std::size_t i = 0; i < initialMask.size(); ++i)
    if (initialMask[i]) inside += magnitude->GetBufferPointer()[i], ++insideCount;
  if (insideCount == 0 || edgeVoxels.empty()) throw std::runtime_error("empty initial mask or no edge voxels");
  inside /= insideCount;
  result.alpha = -(edge - inside) / 6.0;
  result.beta = (edge + inside) / 2.0;

  auto sigmoid = itk::SigmoidImageFilter<FloatImage, FloatImage>::New();
  sigmoid->SetInput(magnitude);
  sigmoid->SetAlpha(result.alpha);
  sigmoid->SetBeta(result.beta);
  sigmoid->SetOutputMinimum(0.0);
  sigmoid->SetOutputMaximum(1.0);


  auto gac = itk::GeodesicActiveContourLevelSetImageFilter<FloatImage, FloatImage>::New();
  gac->SetInput(initialLevelSet(initial));
  gac->SetFeatureImage(sigmoid->GetOutput());
  gac->SetPropagationScaling(options.propagation);
  gac->SetCurvatureScaling(options.curvature);
  gac->SetAdvectionScaling(options.advection);
  gac->SetMaximumRMSError(options.maximumRmsError);
  gac->SetNumberOfIterations(options.iterations);

  gac->Update();
  result.elapsedIterations = static_cast<int>(gac->GetElapsedIterations());
  result.mask = insideOf(gac->GetOutput());
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  return result;
}

}  // namespace itkbaseline
