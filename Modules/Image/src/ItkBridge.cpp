#include "ItkBridge.h"
#include "ItkHeader.h"
#include "ItkImages.h"

#include <algorithm>
#include <vector>

#include <itkGradientRecursiveGaussianImageFilter.h>
#include <itkImage.h>
#include <itkImageFileReader.h>
#include <itkImageFileWriter.h>
#include <itkImageIOBase.h>
#include <itkImageIOFactory.h>
#include <itkMetaImageIOFactory.h>
#include <itkNiftiImageIOFactory.h>
#include <itkNrrdImageIOFactory.h>
#include <itkSignedMaurerDistanceMapImageFilter.h>

#include "dynsub/Error.h"
#include "dynsub/FileNames.h"

namespace dynsub::itkbridge {
namespace {

using GradientImage = itk::Image<itk::CovariantVector<float, 3>, 3>;

// A clear message for a file ITK has no reader for; its size checked
// (inspectHeader).
void inspectFile(const std::string& path) {
  auto io = itk::ImageIOFactory::CreateImageIO(path.c_str(), itk::ImageIOFactory::FileModeEnum::ReadMode);
  if (!io) throw Error(path, "unknown or unreadable image format");
  inspectHeader(path, *io);
}

// The formats ITK reads and writes here, registered explicitly once (GDCM's
// reader is made by readDicom itself).
void registerFormats() {
  static const bool registered = [] {
    itk::NiftiImageIOFactory::RegisterOneFactory();
    itk::NrrdImageIOFactory::RegisterOneFactory();
    itk::MetaImageIOFactory::RegisterOneFactory();
    return true;
  }();
  (void)registered;
}

}  // namespace

void readImage(const std::string& path, Geometry& geometry, std::vector<float>& voxels) {
  registerFormats();
  try {
    inspectFile(path);
    auto reader = itk::ImageFileReader<FloatImage>::New();
    reader->SetFileName(path);
    reader->Update();
    const FloatImage* image = reader->GetOutput();
    geometry = geometryOf(image);
    const float* buffer = image->GetBufferPointer();
    voxels.assign(buffer, buffer + countOf(geometry));
  } catch (const itk::ExceptionObject& e) {
    throw Error(path, std::string("cannot read image: ") + e.GetDescription());
  }
}

void writeLabels(const Geometry& geometry, const std::vector<std::uint8_t>& voxels, const std::string& path) {
  registerFormats();
  try {
    auto writer = itk::ImageFileWriter<MaskImage>::New();
    writer->SetFileName(path);
    writer->SetInput(makeImage<MaskImage>(geometry, voxels));
    writer->UseCompressionOn();
    writer->Update();
  } catch (const itk::ExceptionObject& e) {
    throw Error(path, std::string("cannot write labelmap: ") + e.GetDescription());
  }
}

std::vector<float> recursiveGaussianGradient(const Geometry& geometry, const std::vector<float>& voxels,
                                             double sigma) {
  auto filter = itk::GradientRecursiveGaussianImageFilter<FloatImage, GradientImage>::New();
  filter->SetInput(makeImage<FloatImage>(geometry, voxels));
  filter->SetSigma(sigma);
  filter->Update();
  const auto* buffer = filter->GetOutput()->GetBufferPointer();
  std::vector<float> gradient(3 * voxels.size());
  for (std::size_t v = 0; v < voxels.size(); ++v)
    for (int a = 0; a < 3; ++a) gradient[3 * v + a] = buffer[v][a];
  return gradient;
}

std::vector<float> distanceMap(const Geometry& geometry, const std::vector<std::uint8_t>& mask) {
  auto filter = itk::SignedMaurerDistanceMapImageFilter<MaskImage, FloatImage>::New();
  filter->SetInput(makeImage<MaskImage>(geometry, mask));
  filter->SetUseImageSpacing(true);
  filter->SetSquaredDistance(false);
  filter->SetInsideIsPositive(false);
  filter->SetBackgroundValue(0);
  filter->Update();
  const float* buffer = filter->GetOutput()->GetBufferPointer();
  std::vector<float> distance(buffer, buffer + mask.size());
  // Voxels of the mask get zero or negative values (inside): their distance is 0.
  for (float& d : distance) d = std::max(d, 0.0f);
  return distance;
}

}  // namespace dynsub::itkbridge
