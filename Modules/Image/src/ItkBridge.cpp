#include "ItkBridge.h"
#include "ItkHeader.h"
#include "ItkImages.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include <itkGradientRecursiveGaussianImageFilter.h>
#include <itkImage.h>
#include <itkImageFileReader.h>
#include <itkImageFileWriter.h>
#include <itkImageIOBase.h>
#include <itkImageIOFactory.h>
#include <itkMetaDataObject.h>
#include <itkMetaImageIOFactory.h>
#include <itkNiftiImageIOFactory.h>
#include <itkNrrdImageIOFactory.h>
#include <itkSignedMaurerDistanceMapImageFilter.h>
#include <itkSmoothingRecursiveGaussianImageFilter.h>

#include "dynsub/Error.h"
#include "dynsub/FileNames.h"

namespace dynsub::itkbridge {
namespace {

using GradientImage = itk::Image<itk::CovariantVector<float, 3>, 3>;

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

// The voxels of `io`'s file, of component type T, as float.
template <typename T>
void readConverted(itk::ImageIOBase& io, std::size_t count, std::vector<float>& voxels) {
  std::vector<T> raw(count);
  io.Read(raw.data());
  voxels.resize(count);
  std::transform(raw.begin(), raw.end(), voxels.begin(), [](T v) { return static_cast<float>(v); });
}

// Reads a 3D scalar image whose header `io` has read; false for a component
// type it does not know (left to ImageFileReader).
bool readScalarVolume(itk::ImageIOBase& io, Geometry& geometry, std::vector<float>& voxels) {
  using Component = itk::IOComponentEnum;
  for (unsigned a = 0; a < 3; ++a) {
    geometry.size[a] = static_cast<int>(io.GetDimensions(a));
    geometry.spacing[a] = io.GetSpacing(a);
    geometry.origin[a] = io.GetOrigin(a);
    const std::vector<double> axis = io.GetDirection(a);  // index axis a in physical space
    for (unsigned b = 0; b < 3; ++b) geometry.direction[3 * b + a] = axis[b];
  }
  const std::size_t count = static_cast<std::size_t>(countOf(geometry));
  itk::ImageIORegion whole(3);
  for (unsigned a = 0; a < 3; ++a) {
    whole.SetIndex(a, 0);
    whole.SetSize(a, io.GetDimensions(a));
  }
  io.SetIORegion(whole);
  switch (io.GetComponentType()) {
    case Component::FLOAT:
      voxels.resize(count);
      io.Read(voxels.data());
      return true;
    case Component::UCHAR: readConverted<unsigned char>(io, count, voxels); return true;
    case Component::CHAR: readConverted<signed char>(io, count, voxels); return true;
    case Component::USHORT: readConverted<unsigned short>(io, count, voxels); return true;
    case Component::SHORT: readConverted<short>(io, count, voxels); return true;
    case Component::UINT: readConverted<unsigned int>(io, count, voxels); return true;
    case Component::INT: readConverted<int>(io, count, voxels); return true;
    case Component::DOUBLE: readConverted<double>(io, count, voxels); return true;
    default: return false;
  }
}

}  // namespace

void readImage(const std::string& path, Geometry& geometry, std::vector<float>& voxels) {
  registerFormats();
  try {
    auto io = itk::ImageIOFactory::CreateImageIO(path.c_str(), itk::ImageIOFactory::FileModeEnum::ReadMode);
    if (!io) throw Error(path, "unknown or unreadable image format");
    inspectHeader(path, *io);
    // A 3D scalar image is read by its ImageIO straight into `voxels` (a
    // float file) or through one buffer of its own type: ImageFileReader
    // would add an image of its own and a copy of it into `voxels`, a third
    // of the segment command's page faults. Other files (2D, 4D) go through
    // ImageFileReader, which makes a 3D float image of them.
    if (io->GetNumberOfDimensions() == 3 && io->GetNumberOfComponents() == 1 && readScalarVolume(*io, geometry, voxels))
      return;
    auto reader = itk::ImageFileReader<FloatImage>::New();
    reader->SetImageIO(io);
    reader->SetFileName(path);
    reader->Update();
    const FloatImage* image = reader->GetOutput();
    geometry = geometryOf(image);
    const float* buffer = image->GetBufferPointer();
    voxels.assign(buffer, buffer + countOf(geometry));
  } catch (const itk::ExceptionObject& e) {
    throw Error(path, "cannot read image: " + readableItkMessage(e.GetDescription()));
  }
}

namespace {

// `voxels` on `geometry` written by ITK as an Image, compressed when the
// format allows; `what` names it in the error.
template <typename Image, typename Pixel>
void writeCompressed(const Geometry& geometry, const std::vector<Pixel>& voxels, const std::string& path,
                     const char* what, const std::vector<std::pair<std::string, std::string>>& fields = {}) {
  registerFormats();
  try {
    auto writer = itk::ImageFileWriter<Image>::New();
    writer->SetFileName(path);
    auto image = makeImage<Image>(geometry, voxels);
    for (const auto& [key, value] : fields) itk::EncapsulateMetaData<std::string>(image->GetMetaDataDictionary(), key, value);
    writer->SetInput(image);
    writer->UseCompressionOn();
    writer->Update();
  } catch (const itk::ExceptionObject& e) {
    throw Error(path, std::string("cannot write ") + what + ": " + e.GetDescription());
  }
}

}  // namespace

void writeLabels(const Geometry& geometry, const std::vector<std::uint8_t>& voxels, const std::string& path,
                 const std::vector<std::pair<std::string, std::string>>& fields) {
  writeCompressed<MaskImage>(geometry, voxels, path, "labelmap", fields);
}

void writeImage(const Geometry& geometry, const std::vector<float>& voxels, bool labels, const std::string& path) {
  if (labels) {
    using LabelImage = itk::Image<std::int16_t, 3>;
    std::vector<std::int16_t> values(voxels.size());
    for (std::size_t v = 0; v < voxels.size(); ++v) values[v] = static_cast<std::int16_t>(std::lround(voxels[v]));
    writeCompressed<LabelImage>(geometry, values, path, "image");
  } else {
    writeCompressed<FloatImage>(geometry, voxels, path, "image");
  }
}

std::vector<float> recursiveGaussian(const Geometry& geometry, const std::vector<float>& voxels, double sigma) {
  auto filter = itk::SmoothingRecursiveGaussianImageFilter<FloatImage, FloatImage>::New();
  filter->SetInput(makeImage<FloatImage>(geometry, voxels));
  filter->SetSigma(sigma);
  filter->Update();
  const float* buffer = filter->GetOutput()->GetBufferPointer();
  return std::vector<float>(buffer, buffer + voxels.size());
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
