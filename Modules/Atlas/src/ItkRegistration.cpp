#include "ItkRegistration.h"

#include <algorithm>
#include <cmath>
#include <string>

#include <itkAffineTransform.h>
#include <itkBSplineTransform.h>
#include <itkBSplineTransformInitializer.h>
#include <itkCenteredTransformInitializer.h>
#include <itkImageRegistrationMethodv4.h>
#include <itkLBFGSBOptimizerv4.h>
#include <itkMattesMutualInformationImageToImageMetricv4.h>
#include <itkRegistrationParameterScalesFromPhysicalShift.h>
#include <itkRegularStepGradientDescentOptimizerv4.h>

#include "ItkImages.h"
#include "dynsub/Error.h"

namespace dynsub::itkbridge {

namespace {

using Affine = itk::AffineTransform<double, 3>;
using BSpline = itk::BSplineTransform<double, 3, 3>;
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
  auto method = Method::New();
  method->SetFixedImage(fixedImage);
  method->SetMovingImage(movingImage);
  method->SetMetric(metric);
  method->SetOptimizer(optimizer);
  method->SetInitialTransform(transform);
  method->InPlaceOn();
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

BSplineOutcome registerBSpline(const Geometry& fixedGeometry, const std::vector<float>& fixed,
                               const Geometry& movingGeometry, const std::vector<float>& moving,
                               const AffineArray& affine, const BSplineSettings& settings) {
  const auto fixedImage = makeImage<FloatImage>(fixedGeometry, fixed);
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

  // Control points about gridSpacingMm apart over the fixed image's extent.
  auto transform = BSpline::New();
  BSpline::MeshSizeType mesh;
  for (int a = 0; a < 3; ++a) {
    const double extent = fixedGeometry.spacing[a] * (fixedGeometry.size[a] - 1);
    mesh[a] = std::max(1u, static_cast<unsigned>(std::lround(extent / settings.gridSpacingMm)));
  }
  auto initializer = itk::BSplineTransformInitializer<BSpline, FloatImage>::New();
  initializer->SetTransform(transform);
  initializer->SetImage(fixedImage);
  initializer->SetTransformDomainMeshSize(mesh);
  initializer->InitializeTransform();
  transform->SetIdentity();

  const unsigned count = transform->GetNumberOfParameters();
  auto optimizer = itk::LBFGSBOptimizerv4::New();
  itk::LBFGSBOptimizerv4::BoundSelectionType select(count);
  itk::LBFGSBOptimizerv4::BoundValueType lower(count), upper(count);
  select.Fill(2);  // both bounds: no control point moves farther than largestShiftMm
  lower.Fill(-settings.largestShiftMm);
  upper.Fill(settings.largestShiftMm);
  optimizer->SetBoundSelection(select);
  optimizer->SetLowerBound(lower);
  optimizer->SetUpperBound(upper);
  optimizer->SetCostFunctionConvergenceFactor(1e7);
  optimizer->SetGradientConvergenceTolerance(1e-5);
  optimizer->SetNumberOfIterations(settings.iterations);
  optimizer->SetMaximumNumberOfFunctionEvaluations(2 * settings.iterations);
  optimizer->SetMaximumNumberOfCorrections(5);

  using Method = itk::ImageRegistrationMethodv4<FloatImage, FloatImage, BSpline>;
  auto method = Method::New();
  method->SetFixedImage(fixedImage);
  method->SetMovingImage(movingImage);
  method->SetMetric(mattes(settings.histogramBins));
  method->SetOptimizer(optimizer);
  method->SetMovingInitialTransform(start);  // points pass the B-spline, then the affine
  method->SetInitialTransform(transform);
  method->InPlaceOn();
  setPyramid(*method, fixedImage.GetPointer(), settings.levelsMm);
  method->SetMetricSamplingStrategy(Sampling::RANDOM);
  method->SetMetricSamplingPercentage(settings.samplingFraction);
  method->MetricSamplingReinitializeSeed(kSamplingSeed);
  // L-BFGS-B warns on every run that it ignores the parameter scales the
  // registration sets; the control points' shifts are all in mm, so scales
  // of one are right.
  const bool warnings = itk::Object::GetGlobalWarningDisplay();
  itk::Object::GlobalWarningDisplayOff();
  try {
    method->Update();
  } catch (const itk::ExceptionObject& e) {
    itk::Object::SetGlobalWarningDisplay(warnings);
    throw Error(std::string("the deformable registration failed: ") + e.GetDescription());
  }
  itk::Object::SetGlobalWarningDisplay(warnings);

  BSplineOutcome outcome;
  outcome.metric = optimizer->GetValue();
  outcome.iterations = static_cast<int>(optimizer->GetCurrentIteration());
  const BSpline* warp = method->GetTransform();
  Geometry& field = outcome.field;
  field.origin = fixedGeometry.origin;
  field.direction = fixedGeometry.direction;
  for (int a = 0; a < 3; ++a) {
    const double extent = fixedGeometry.spacing[a] * (fixedGeometry.size[a] - 1);
    const double step = std::max(fixedGeometry.spacing[a], settings.levelsMm.back());
    field.size[a] = 1 + static_cast<int>(std::ceil(extent / step));
    field.spacing[a] = field.size[a] > 1 ? extent / (field.size[a] - 1) : step;
  }
  const auto fieldImage = makeImage<FloatImage>(field, std::vector<float>(countOf(field), 0.0f));
  outcome.displacement.resize(3 * static_cast<std::size_t>(countOf(field)));
  std::size_t n = 0;
  FloatImage::IndexType index;
  for (int k = 0; k < field.size[2]; ++k)
    for (int j = 0; j < field.size[1]; ++j)
      for (int i = 0; i < field.size[0]; ++i) {
        index[0] = i;
        index[1] = j;
        index[2] = k;
        FloatImage::PointType x;
        fieldImage->TransformIndexToPhysicalPoint(index, x);
        const auto y = warp->TransformPoint(x);
        for (int a = 0; a < 3; ++a) outcome.displacement[n++] = static_cast<float>(y[a] - x[a]);
      }
  return outcome;
}

}  // namespace dynsub::itkbridge
