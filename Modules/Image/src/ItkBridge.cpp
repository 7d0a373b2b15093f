#include "ItkBridge.h"
#include "ItkImages.h"

#include <algorithm>
#include <filesystem>

#include <itkGDCMImageIO.h>
#include <itkGDCMSeriesFileNames.h>
#include <itkGradientRecursiveGaussianImageFilter.h>
#include <itkImage.h>
#include <itkImageFileReader.h>
#include <itkImageFileWriter.h>
#include <itkImageIOBase.h>
#include <itkImageIOFactory.h>
#include <itkImageSeriesReader.h>
#include <itkSignedMaurerDistanceMapImageFilter.h>

#include "dynsub/Error.h"
#include "dynsub/FileNames.h"

namespace dynsub::itkbridge {
namespace {

namespace fs = std::filesystem;
using GradientImage = itk::Image<itk::CovariantVector<float, 3>, 3>;

Geometry geometryOf(const FloatImage* image) {
  Geometry g;
  for (int a = 0; a < 3; ++a) {
    g.size[a] = static_cast<int>(image->GetLargestPossibleRegion().GetSize()[a]);
    g.spacing[a] = image->GetSpacing()[a];
    g.origin[a] = image->GetOrigin()[a];
    for (int b = 0; b < 3; ++b) g.direction[3 * a + b] = image->GetDirection()(a, b);
  }
  return g;
}

long long countOf(const Geometry& g) { return static_cast<long long>(g.size[0]) * g.size[1] * g.size[2]; }

// A clear message for a file ITK has no reader for, and a size check ITK
// leaves out (the number of dimensions is checked by readVolume, for files and
// DICOM series alike).
void inspectFile(const std::string& path) {
  auto io = itk::ImageIOFactory::CreateImageIO(path.c_str(), itk::ImageIOFactory::FileModeEnum::ReadMode);
  if (!io) throw Error(path, "unknown or unreadable image format");
  io->SetFileName(path);
  io->ReadImageInformation();
  // NB: ITK's NIfTI reader fills a truncated uncompressed .nii with zeros
  // without complaint (compressed files fail in zlib), so the size is checked:
  // a NIfTI header is at least 348 bytes.
  if (lowerCaseExtension(path) == ".nii") {
    const auto needed = static_cast<std::uintmax_t>(io->GetImageSizeInBytes()) + 348;
    const auto actual = fs::file_size(path);
    if (actual < needed)
      throw Error(path, "truncated: " + std::to_string(actual) + " bytes, the header announces at least " +
                            std::to_string(needed));
  }
}

}  // namespace

void readImage(const std::string& path, Geometry& geometry, std::vector<float>& voxels) {
  try {
    FloatImage::Pointer image;
    std::error_code ignored;
    if (fs::is_directory(path, ignored)) {
      auto names = itk::GDCMSeriesFileNames::New();
      names->SetUseSeriesDetails(true);
      names->SetDirectory(path);
      const auto series = names->GetSeriesUIDs();
      if (series.empty()) throw Error(path, "directory holds no DICOM series");
      if (series.size() > 1)
        throw Error(path, "directory holds " + std::to_string(series.size()) + " DICOM series; give one series");
      auto reader = itk::ImageSeriesReader<FloatImage>::New();
      reader->SetImageIO(itk::GDCMImageIO::New());
      reader->SetFileNames(names->GetFileNames(series.front()));
      reader->Update();
      image = reader->GetOutput();
    } else {
      inspectFile(path);
      auto reader = itk::ImageFileReader<FloatImage>::New();
      reader->SetFileName(path);
      reader->Update();
      image = reader->GetOutput();
    }
    geometry = geometryOf(image);
    const float* buffer = image->GetBufferPointer();
    voxels.assign(buffer, buffer + countOf(geometry));
  } catch (const itk::ExceptionObject& e) {
    throw Error(path, std::string("cannot read image: ") + e.GetDescription());
  }
}

void writeLabels(const Geometry& geometry, const std::vector<std::uint8_t>& voxels, const std::string& path) {
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
