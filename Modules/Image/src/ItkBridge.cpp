#include "ItkBridge.h"
#include "ItkImages.h"
#include "FileChecks.h"

#include <algorithm>
#include <filesystem>
#include <cctype>
#include <iostream>
#include <sstream>
#include <vector>

#include <gdcmReader.h>
#include <gdcmTrace.h>

#include <itkGDCMImageIO.h>
#include <itkGDCMSeriesFileNames.h>
#include <itkGradientRecursiveGaussianImageFilter.h>
#include <itkImage.h>
#include <itkImageFileReader.h>
#include <itkImageFileWriter.h>
#include <itkImageIOBase.h>
#include <itkImageIOFactory.h>
#include <itkImageSeriesReader.h>
#include <itkMetaDataObject.h>
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


// After the project's own checks of the file (FileChecks.h: checkImageFile,
// made by readVolume before it calls readImage): a clear message for a file
// ITK has no reader for, and for any format an image too large for memory is
// refused before it is allocated (the number of dimensions is checked by
// readVolume, for files and DICOM series alike).
void inspectFile(const std::string& path) {
  auto io = itk::ImageIOFactory::CreateImageIO(path.c_str(), itk::ImageIOFactory::FileModeEnum::ReadMode);
  if (!io) throw Error(path, "unknown or unreadable image format");
  io->SetFileName(path);
  io->ReadImageInformation();
  std::uintmax_t voxels = 1;
  for (unsigned a = 0; a < io->GetNumberOfDimensions(); ++a) {
    const std::uintmax_t size = io->GetDimensions(a);
    if (size != 0 && voxels > UINTMAX_MAX / size) throw Error(path, "an image size that does not fit in 64 bits");
    voxels *= size;
  }
  filechecks::requireMemoryFor(path, voxels);
}

// ITK's global warning display off for a scope.
class WarningsOff {
 public:
  WarningsOff() : was_(itk::Object::GetGlobalWarningDisplay()) { itk::Object::SetGlobalWarningDisplay(false); }
  ~WarningsOff() { itk::Object::SetGlobalWarningDisplay(was_); }
  WarningsOff(const WarningsOff&) = delete;
  WarningsOff& operator=(const WarningsOff&) = delete;

 private:
  bool was_;
};


// The files of a directory that say they are DICOM, each walked (DicomWalk)
// before GDCM sees any of them.
struct DicomFile {
  fs::path path, canonical;
  bool walked;  // wholly checked by the walk (else GDCM must tell)
};

std::vector<DicomFile> walkDicomFiles(const std::string& directory) {
  std::vector<DicomFile> files;
  for (const auto& entry : fs::directory_iterator(directory))
    if (entry.is_regular_file() && filechecks::isDicomFile(entry.path()))
      files.push_back({entry.path(), fs::weakly_canonical(entry.path()), filechecks::walkDicomFile(entry.path())});
  return files;
}

// GDCM leaves out of a series the files it cannot parse, and reads a slice
// whose pixel data is cut short with only a warning: either would silently
// become a gap or a slice of garbage. So every file of the series must be
// whole: walked (`dicomFiles`), or else read by GDCM with its warnings caught
// to tell; and every other DICOM file of the directory is an error.
void requireWholeSeries(const std::vector<std::string>& files, const std::vector<DicomFile>& dicomFiles) {
  std::vector<fs::path> inSeries;
  for (const std::string& file : files) {
    inSeries.push_back(fs::weakly_canonical(file));
    const auto known = std::find_if(dicomFiles.begin(), dicomFiles.end(),
                                    [&](const DicomFile& d) { return d.canonical == inSeries.back(); });
    if (known != dicomFiles.end() && known->walked) continue;
    // ITK turns GDCM's warnings off; they are on, and caught, while checking.
    const bool warningsWereOn = gdcm::Trace::GetWarningFlag();
    std::ostringstream warnings;
    gdcm::Trace::WarningOn();
    gdcm::Trace::SetWarningStream(warnings);
    gdcm::Reader reader;
    reader.SetFileName(file.c_str());
    const bool read = reader.Read();
    gdcm::Trace::SetWarningStream(std::cerr);
    gdcm::Trace::SetWarning(warningsWereOn);
    if (!read || warnings.str().find("Incomplete Pixel Data") != std::string::npos)
      throw Error(file, "a DICOM file of the series is truncated or corrupt");
  }
  for (const DicomFile& d : dicomFiles) {
    // A media directory (DICOMDIR) indexes the files; it is not part of a series.
    std::string name = d.path.filename().string();
    std::transform(name.begin(), name.end(), name.begin(), [](unsigned char c) { return std::toupper(c); });
    if (name == "DICOMDIR") continue;
    if (std::find(inSeries.begin(), inSeries.end(), d.canonical) == inSeries.end())
      throw Error(d.path.string(), "a DICOM file that cannot be read with the rest of the series "
                                   "(truncated or corrupt?)");
  }
}

// ITK reads slices that are not evenly spaced (a missing slice, a mixed
// acquisition) onto an even grid, with a warning only: a deviation beyond 1 %
// of the slice spacing is an error here.
void requireEvenSlices(const std::string& directory, const FloatImage& image) {
  double deviation = 0;
  if (!itk::ExposeMetaData<double>(image.GetMetaDataDictionary(), "ITK_non_uniform_sampling_deviation", deviation))
    return;
  const double spacing = image.GetSpacing()[2];
  if (deviation > 0.01 * spacing)
    throw Error(directory, "the DICOM slices are not evenly spaced (a slice missing?): they deviate by " +
                               std::to_string(deviation) + " mm from the spacing of " + std::to_string(spacing) +
                               " mm");
}

void readImage(const std::string& path, Geometry& geometry, std::vector<float>& voxels) {
  try {
    FloatImage::Pointer image;
    std::error_code ignored;
    if (fs::is_directory(path, ignored)) {
      const std::vector<DicomFile> dicomFiles = walkDicomFiles(path);
      // ITK's warnings (no series, uneven slices) would only repeat, less
      // clearly, what the checks here report as errors.
      const WarningsOff quiet;
      auto names = itk::GDCMSeriesFileNames::New();
      names->SetUseSeriesDetails(true);
      names->SetDirectory(path);
      const auto series = names->GetSeriesUIDs();
      if (series.empty()) throw Error(path, "directory holds no DICOM series");
      if (series.size() > 1)
        throw Error(path, "directory holds " + std::to_string(series.size()) + " DICOM series; give one series");
      const std::vector<std::string> files = names->GetFileNames(series.front());
      requireWholeSeries(files, dicomFiles);
      auto reader = itk::ImageSeriesReader<FloatImage>::New();
      reader->SetImageIO(itk::GDCMImageIO::New());
      reader->SetFileNames(files);
      reader->Update();
      image = reader->GetOutput();
      requireEvenSlices(path, *image);
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

bool readGeometry(const std::string& path, Geometry& geometry) {
  try {
    // The reader's own output information, so the geometry is the one its
    // Update would give (readImage).
    auto reader = itk::ImageFileReader<FloatImage>::New();
    reader->SetFileName(path);
    reader->UpdateOutputInformation();
    const itk::ImageIOBase* io = reader->GetImageIO();
    if (io->GetNumberOfDimensions() != 3 || io->GetNumberOfComponents() != 1) return false;
    geometry = geometryOf(reader->GetOutput());
    return true;
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

}  // namespace
}  // namespace dynsub::itkbridge

// The library's one exported symbol (it is built with hidden visibility).
extern "C" __attribute__((visibility("default"))) const dynsub::itkbridge::Functions* dynsubItkBridgeFunctions() {
  using namespace dynsub::itkbridge;
  static const Functions table{&readImage, &readGeometry, &writeLabels, &recursiveGaussianGradient, &distanceMap};
  return &table;
}
