#include "ItkBridge.h"
#include "ItkImages.h"

#include <algorithm>
#include <filesystem>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <set>
#include <sstream>

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

// Whether a file says it is DICOM: "DICM" after the 128-byte preamble.
bool isDicomFile(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  char magic[4] = {};
  in.seekg(128);
  return in.read(magic, 4) && std::string(magic, 4) == "DICM";
}

// GDCM, as Debian builds it, aborts the process (a failed assertion) on a
// file cut short before its pixel data. So the elements of each DICOM file
// are walked first, and each must fit in the file: the meta header (explicit
// VR, little endian) and a data set in the two uncompressed little-endian
// transfer syntaxes. The walk stops, trusting GDCM with the rest, at an element
// of undefined length (a sequence, encapsulated pixel data) or at a data set
// in another transfer syntax.
void requireWholeDicomFile(const fs::path& file) {
  const std::uintmax_t size = fs::file_size(file);
  std::ifstream in(file, std::ios::binary);
  auto fail = [&](const std::string& what) { throw Error(file.string(), "a truncated DICOM file: " + what); };
  auto read = [&](unsigned char* bytes, int n) { return static_cast<bool>(in.read(reinterpret_cast<char*>(bytes), n)); };
  auto little = [](const unsigned char* b, int n) {
    std::uintmax_t v = 0;
    for (int i = n - 1; i >= 0; --i) v = (v << 8) | b[i];
    return v;
  };
  // Explicit VRs with a 4-byte length (after 2 reserved bytes); the others have 2.
  static const std::set<std::string> longLength = {"OB", "OD", "OF", "OL", "OV", "OW", "SQ",
                                                   "SV", "UC", "UN", "UR", "UT", "UV"};
  std::uintmax_t at = 132;
  bool meta = true, explicitVr = true;
  std::string syntax;
  while (at < size) {
    in.seekg(static_cast<std::streamoff>(at));
    unsigned char tag[4];
    if (size - at < 8 || !read(tag, 4)) fail("an element is cut short at byte " + std::to_string(at));
    const unsigned group = static_cast<unsigned>(little(tag, 2));
    if (meta && group != 0x0002) {
      meta = false;
      if (syntax == "1.2.840.10008.1.2") {
        explicitVr = false;
      } else if (syntax != "1.2.840.10008.1.2.1") {
        return;  // compressed, deflated or big endian: GDCM's alone
      }
    }
    std::uintmax_t length = 0, header = 8;
    unsigned char rest[8];
    if (explicitVr) {
      if (!read(rest, 4)) fail("an element is cut short at byte " + std::to_string(at));
      const std::string vr(reinterpret_cast<char*>(rest), 2);
      if (longLength.count(vr)) {
        unsigned char four[4];
        if (!read(four, 4)) fail("an element is cut short at byte " + std::to_string(at));
        length = little(four, 4);
        header = 12;
      } else {
        length = little(rest + 2, 2);
      }
    } else {
      if (!read(rest, 4)) fail("an element is cut short at byte " + std::to_string(at));
      length = little(rest, 4);
    }
    if (length == 0xFFFFFFFFu) return;  // undefined length: GDCM's alone
    if (at + header + length > size) {
      char name[16];
      std::snprintf(name, sizeof name, "(%04x,%04x)", group, static_cast<unsigned>(little(tag + 2, 2)));
      fail(std::string("element ") + name + " needs " + std::to_string(length) + " bytes, the file has " +
           std::to_string(size - at - header));
    }
    if (meta && little(tag + 2, 2) == 0x0010) {  // (0002,0010) transfer syntax UID
      std::string value(length, '\0');
      in.read(value.data(), static_cast<std::streamsize>(length));
      while (!value.empty() && (value.back() == '\0' || value.back() == ' ')) value.pop_back();
      syntax = value;
    }
    at += header + length;
  }
}

// GDCM leaves out of a series the files it cannot parse, and reads a slice
// whose pixel data is cut short with only a warning: either would silently
// become a gap or a slice of garbage. So every file of the series must read
// whole (GDCM's warnings are caught to tell), and every other file of the
// directory that says it is DICOM ("DICM" after the 128-byte preamble) is an
// error too.
void requireWholeSeries(const std::string& directory, const std::vector<std::string>& files) {
  std::vector<fs::path> inSeries;
  // ITK turns GDCM's warnings off; they are on, and caught, while checking.
  const bool warningsWereOn = gdcm::Trace::GetWarningFlag();
  for (const std::string& file : files) {
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
    inSeries.push_back(fs::weakly_canonical(file));
  }
  for (const auto& entry : fs::directory_iterator(directory)) {
    if (!entry.is_regular_file() || !isDicomFile(entry.path())) continue;
    if (std::find(inSeries.begin(), inSeries.end(), fs::weakly_canonical(entry.path())) == inSeries.end())
      throw Error(entry.path().string(), "a DICOM file that cannot be read with the rest of the series "
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

}  // namespace

void readImage(const std::string& path, Geometry& geometry, std::vector<float>& voxels) {
  try {
    FloatImage::Pointer image;
    std::error_code ignored;
    if (fs::is_directory(path, ignored)) {
      for (const auto& entry : fs::directory_iterator(path))
        if (entry.is_regular_file() && isDicomFile(entry.path())) requireWholeDicomFile(entry.path());
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
      requireWholeSeries(path, files);
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
