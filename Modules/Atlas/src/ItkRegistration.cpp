#include "ItkRegistration.h"

#include <algorithm>
#include <cmath>
#include <string>

#include <itkAffineTransform.h>
#include <itkCenteredTransformInitializer.h>
#include <itkImageRegistrationMethodv4.h>
#include <itkGaussianSmoothingOnUpdateDisplacementFieldTransform.h>
#include <itkGradientDescentOptimizerv4.h>
#include <itkResampleImageFilter.h>
#include <itkSmoothingRecursiveGaussianImageFilter.h>
#include <itkMattesMutualInformationImageToImageMetricv4.h>
#include <itkRegistrationParameterScalesFromPhysicalShift.h>
#include <itkRegularStepGradientDescentOptimizerv4.h>

#include "ItkImages.h"
#include "dynsub/Error.h"

namespace dynsub::itkbridge {

namespace {

using Affine = itk::AffineTransform<double, 3>;
using Metric = itk::MattesMutualInformationImageToImageMetricv4<FloatImage, FloatImage>;
using Sampling = itk::ImageRegistrationMethodv4Enums::MetricSamplingStrategy;

// The random samples are the same from run to run, so a registration is too.
constexpr int kSamplingSeed = 1;

// A level of `levelsMm` on `image`'s grid: the shrink factor per axis that
// brings its voxels to about that size (never below 1), and the Gaussian's
// sigma (mm) that keeps the shrunk image from aliasing (half the level).
template <typename Method>
void setPyramid(Method& method, const FloatImage* image, const std::vector<double>& levelsMm) {
  const unsigned levels = static_cast<unsigned>(levelsMm.size());
  method.SetNumberOfLevels(levels);
  typename Method::SmoothingSigmasArrayType sigmas(levels);
  for (unsigned level = 0; level < levels; ++level) {
    typename Method::ShrinkFactorsPerDimensionContainerType factors;
    for (int a = 0; a < 3; ++a)
      factors[a] = std::max(1u, static_cast<unsigned>(std::lround(levelsMm[level] / image->GetSpacing()[a])));
    method.SetShrinkFactorsPerDimension(level, factors);
    sigmas[level] = levelsMm[level] > image->GetSpacing()[0] ? 0.5 * levelsMm[level] : 0.0;
  }
  method.SetSmoothingSigmasPerLevel(sigmas);
  method.SetSmoothingSigmasAreSpecifiedInPhysicalUnits(true);
}

// A v4 registration method of `fixed` and `moving` by `metric`, whose
// optimizer changes `transform` in place.
template <typename Method, typename Optimizer, typename Transform>
typename Method::Pointer registrationMethod(const FloatImage* fixed, const FloatImage* moving, Metric* metric,
                                            Optimizer* optimizer, Transform* transform) {
  auto method = Method::New();
  method->SetFixedImage(fixed);
  method->SetMovingImage(moving);
  method->SetMetric(metric);
  method->SetOptimizer(optimizer);
  method->SetInitialTransform(transform);
  method->InPlaceOn();
  return method;
}

Metric::Pointer mattes(int bins) {
  auto metric = Metric::New();
  metric->SetNumberOfHistogramBins(bins);
  metric->SetUseFixedImageGradientFilter(false);
  metric->SetUseMovingImageGradientFilter(false);
  return metric;
}

}  // namespace

AffineOutcome registerAffine(const Geometry& fixedGeometry, const std::vector<float>& fixed,
                             const Geometry& movingGeometry, const std::vector<float>& moving,
                             const AffineSettings& settings) {
  const auto fixedImage = makeImage<FloatImage>(fixedGeometry, fixed);
  const auto movingImage = makeImage<FloatImage>(movingGeometry, moving);

  auto transform = Affine::New();
  auto initializer = itk::CenteredTransformInitializer<Affine, FloatImage, FloatImage>::New();
  initializer->SetTransform(transform);
  initializer->SetFixedImage(fixedImage);
  initializer->SetMovingImage(movingImage);
  initializer->MomentsOn();
  initializer->InitializeTransform();

  auto metric = mattes(settings.histogramBins);
  auto scales = itk::RegistrationParameterScalesFromPhysicalShift<Metric>::New();
  scales->SetMetric(metric);
  auto optimizer = itk::RegularStepGradientDescentOptimizerv4<double>::New();
  optimizer->SetScalesEstimator(scales);
  // The first step of each level moves no point more than a voxel of the
  // fixed image (the optimizer's default step); it halves as the direction turns.
  optimizer->SetDoEstimateLearningRateOnce(true);
  optimizer->SetMinimumStepLength(1e-3);
  optimizer->SetRelaxationFactor(0.5);
  optimizer->SetGradientMagnitudeTolerance(1e-6);
  optimizer->SetNumberOfIterations(settings.iterations);

  using Method = itk::ImageRegistrationMethodv4<FloatImage, FloatImage, Affine>;
  auto method = registrationMethod<Method>(fixedImage.GetPointer(), movingImage.GetPointer(), metric.GetPointer(),
                                           optimizer.GetPointer(), transform.GetPointer());
  setPyramid(*method, fixedImage.GetPointer(), settings.levelsMm);
  method->SetMetricSamplingStrategy(Sampling::RANDOM);
  method->SetMetricSamplingPercentage(settings.samplingFraction);
  method->MetricSamplingReinitializeSeed(kSamplingSeed);

  AffineOutcome outcome;
  struct Counter : itk::Command {
    int* count = nullptr;
    void Execute(itk::Object*, const itk::EventObject&) override { ++*count; }
    void Execute(const itk::Object*, const itk::EventObject&) override { ++*count; }
  };
  itk::SmartPointer<Counter> counter = new Counter;
  counter->UnRegister();
  counter->count = &outcome.iterations;
  optimizer->AddObserver(itk::IterationEvent(), counter);
  try {
    method->Update();
  } catch (const itk::ExceptionObject& e) {
    throw Error(std::string("the affine registration failed: ") + e.GetDescription());
  }

  const Affine* result = method->GetTransform();
  const auto& matrix = result->GetMatrix();
  const auto& offset = result->GetOffset();
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) outcome.transform[4 * r + c] = matrix(r, c);
    outcome.transform[4 * r + 3] = offset[r];
  }
  outcome.metric = optimizer->GetValue();
  return outcome;
}

DeformableOutcome registerDeformable(const Geometry& fixedGeometry, const std::vector<float>& fixed,
                                     const Geometry& movingGeometry, const std::vector<float>& moving,
                                     const AffineArray& affine, const DeformableSettings& settings) {
  // The fixed region smoothed and resampled to the field's grid: the
  // registration runs on that grid alone.
  Geometry grid = fixedGeometry;
  for (int a = 0; a < 3; ++a) {
    const double extent = fixedGeometry.spacing[a] * (fixedGeometry.size[a] - 1);
    const double step = std::max(fixedGeometry.spacing[a], settings.levelMm);
    grid.size[a] = 1 + static_cast<int>(std::ceil(extent / step));
    grid.spacing[a] = grid.size[a] > 1 ? extent / (grid.size[a] - 1) : step;
  }
  auto fixedImage = makeImage<FloatImage>(fixedGeometry, fixed);
  const double sigma = 0.5 * settings.levelMm;
  FloatImage::Pointer smoothed = fixedImage;
  if (sigma > fixedGeometry.spacing[0]) {
    auto smoother = itk::SmoothingRecursiveGaussianImageFilter<FloatImage, FloatImage>::New();
    smoother->SetInput(fixedImage);
    smoother->SetSigma(sigma);
    smoother->Update();
    smoothed = smoother->GetOutput();
  }
  const auto gridImage = makeImage<FloatImage>(grid, std::vector<float>(countOf(grid), 0.0f));
  auto resampler = itk::ResampleImageFilter<FloatImage, FloatImage>::New();
  resampler->SetInput(smoothed);
  resampler->UseReferenceImageOn();
  resampler->SetReferenceImage(gridImage);
  resampler->Update();
  const FloatImage::Pointer fixedOnGrid = resampler->GetOutput();
  const auto movingImage = makeImage<FloatImage>(movingGeometry, moving);

  auto start = Affine::New();
  Affine::MatrixType matrix;
  Affine::OutputVectorType offset;
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) matrix(r, c) = affine[4 * r + c];
    offset[r] = affine[4 * r + 3];
  }
  start->SetMatrix(matrix);
  start->SetOffset(offset);

  using FieldTransform = itk::GaussianSmoothingOnUpdateDisplacementFieldTransform<double, 3>;
  using FieldImage = FieldTransform::DisplacementFieldType;
  auto displacement = FieldImage::New();
  displacement->CopyInformation(fixedOnGrid);
  displacement->SetRegions(fixedOnGrid->GetLargestPossibleRegion());
  displacement->Allocate();
  displacement->FillBuffer(FieldImage::PixelType(0.0));
  auto transform = FieldTransform::New();
  transform->SetDisplacementField(displacement);
  // The operator's variances are in voxels of the field's grid.
  const double voxel = std::max({grid.spacing[0], grid.spacing[1], grid.spacing[2]});
  transform->SetGaussianSmoothingVarianceForTheUpdateField(std::pow(settings.updateSigmaMm / voxel, 2));
  transform->SetGaussianSmoothingVarianceForTheTotalField(std::pow(settings.totalSigmaMm / voxel, 2));

  auto metric = mattes(settings.histogramBins);
  auto scales = itk::RegistrationParameterScalesFromPhysicalShift<Metric>::New();
  scales->SetMetric(metric);
  auto optimizer = itk::GradientDescentOptimizerv4::New();
  optimizer->SetScalesEstimator(scales);
  // Every step moves no voxel more than a quarter of a field voxel.
  optimizer->SetLearningRate(1.0);
  optimizer->SetMaximumStepSizeInPhysicalUnits(0.25 * voxel);
  optimizer->SetDoEstimateLearningRateAtEachIteration(true);
  optimizer->SetDoEstimateLearningRateOnce(false);
  optimizer->SetNumberOfIterations(settings.iterations);
  optimizer->SetConvergenceWindowSize(10);
  optimizer->SetMinimumConvergenceValue(1e-6);

  using Method = itk::ImageRegistrationMethodv4<FloatImage, FloatImage, FieldTransform>;
  auto method = registrationMethod<Method>(fixedOnGrid.GetPointer(), movingImage.GetPointer(), metric.GetPointer(),
                                           optimizer.GetPointer(), transform.GetPointer());
  method->SetMovingInitialTransform(start);  // points pass the field, then the affine
  method->SetNumberOfLevels(1);
  Method::ShrinkFactorsArrayType shrink(1);
  shrink[0] = 1;
  method->SetShrinkFactorsPerLevel(shrink);
  Method::SmoothingSigmasArrayType sigmas(1);
  sigmas[0] = 0;
  method->SetSmoothingSigmasPerLevel(sigmas);
  method->SetMetricSamplingStrategy(Sampling::NONE);
  try {
    method->Update();
  } catch (const itk::ExceptionObject& e) {
    throw Error(std::string("the deformable registration failed: ") + e.GetDescription());
  }

  DeformableOutcome outcome;
  outcome.metric = optimizer->GetValue();
  outcome.iterations = static_cast<int>(optimizer->GetCurrentIteration());
  outcome.field = grid;
  const FieldImage* result = transform->GetDisplacementField();
  outcome.displacement.resize(3 * static_cast<std::size_t>(countOf(grid)));
  const auto* values = result->GetBufferPointer();
  for (long long v = 0; v < countOf(grid); ++v)
    for (int a = 0; a < 3; ++a) outcome.displacement[3 * v + a] = static_cast<float>(values[v][a]);
  return outcome;
}

}  // namespace dynsub::itkbridge
