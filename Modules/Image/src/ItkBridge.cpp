#include "ItkBridge.h"
#include "ItkImages.h"

#include <algorithm>
#include <filesystem>
#include <cctype>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <set>
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
#include <zlib.h>

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

// The number of bytes a gzip file inflates to. Throws when its stream is cut
// short or corrupt.
std::uintmax_t inflatedSize(const std::string& path) {
  gzFile file = gzopen(path.c_str(), "rb");
  if (!file) throw Error(path, "cannot be opened");
  std::vector<char> buffer(1 << 20);
  std::uintmax_t total = 0;
  int read = 0;
  while ((read = gzread(file, buffer.data(), static_cast<unsigned>(buffer.size()))) > 0) total += read;
  int code = Z_OK;
  std::string message = gzerror(file, &code);
  gzclose(file);
  if (message.rfind(path + ": ", 0) == 0) message.erase(0, path.size() + 2);  // zlib puts the path first
  if (read < 0 || (code != Z_OK && code != Z_STREAM_END))
    throw Error(path, "truncated or corrupt compressed data (" + message + ") after " + std::to_string(total) +
                          " bytes");
  return total;
}

// Whether a MetaImage file's data is all there: after its header (LOCAL) or
// in its data file, CompressedDataSize bytes when compressed, else `voxelBytes`.
// ITK reads a short compressed .mha without complaint. Lists and patterns of
// slice files are left to ITK.
void checkMetaImageSize(const std::string& path, std::uintmax_t voxelBytes) {
  std::ifstream in(path, std::ios::binary);
  auto trim = [](const std::string& text) {
    const auto first = text.find_first_not_of(" \t\r"), last = text.find_last_not_of(" \t\r");
    return first == std::string::npos ? std::string() : text.substr(first, last - first + 1);
  };
  std::string line, dataFile;
  bool compressed = false;
  std::uintmax_t compressedSize = 0;
  while (dataFile.empty() && std::getline(in, line)) {
    const auto equals = line.find('=');
    if (equals == std::string::npos) continue;
    const std::string key = trim(line.substr(0, equals)), value = trim(line.substr(equals + 1));
    if (key == "CompressedData") compressed = value == "True" || value == "true";
    if (key == "CompressedDataSize") compressedSize = std::strtoull(value.c_str(), nullptr, 10);
    if (key == "ElementDataFile") dataFile = value;
  }
  std::uintmax_t available = 0;
  std::string source = path;
  if (dataFile == "LOCAL") {
    available = fs::file_size(path) - static_cast<std::uintmax_t>(std::max<std::streamoff>(in.tellg(), 0));
  } else if (!dataFile.empty() && dataFile.find_first_of("% ") == std::string::npos && dataFile != "LIST") {
    source = (fs::path(path).parent_path() / dataFile).string();
    std::error_code error;
    available = fs::file_size(source, error);
    if (error) throw Error(path, "its data file " + source + " cannot be read");
  } else {
    return;
  }
  const std::uintmax_t needed = compressed ? compressedSize : voxelBytes;
  if (available < needed)
    throw Error(source, "truncated: " + std::to_string(available) + " bytes of data, the header announces " +
                            std::to_string(needed));
}

// A clear message for a file ITK has no reader for, and a size check ITK
// leaves out (the number of dimensions is checked by readVolume, for files and
// DICOM series alike).
void inspectFile(const std::string& path) {
  auto io = itk::ImageIOFactory::CreateImageIO(path.c_str(), itk::ImageIOFactory::FileModeEnum::ReadMode);
  if (!io) throw Error(path, "unknown or unreadable image format");
  io->SetFileName(path);
  io->ReadImageInformation();
  // NB: ITK's NIfTI reader fills a truncated .nii, or a .nii.gz whose gzip
  // stream is cut short, with zeros without complaint. So the (inflated) size
  // is checked: a NIfTI header is at least 348 bytes.
  const std::string extension = lowerCaseExtension(path);
  const bool gzipped = extension == ".gz" && lowerCaseExtension(path.substr(0, path.size() - 3)) == ".nii";
  if (extension == ".nii" || gzipped) {
    const auto needed = static_cast<std::uintmax_t>(io->GetImageSizeInBytes()) + 348;
    const auto actual = gzipped ? inflatedSize(path) : fs::file_size(path);
    if (actual < needed)
      throw Error(path, "truncated: " + std::to_string(actual) + (gzipped ? " bytes inflated" : " bytes") +
                            ", the header announces at least " + std::to_string(needed));
  }
  if (extension == ".mha" || extension == ".mhd") checkMetaImageSize(path, io->GetImageSizeInBytes());
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
// file cut short before its pixel data. So the elements of each DICOM file are
// walked first, and each must fit in the file: the meta header (explicit VR,
// little endian), then a data set in either uncompressed little-endian
// transfer syntax (explicit or implicit VR), sequences and items of undefined
// length included, and encapsulated pixel data fragment by fragment. A data
// set in another transfer syntax (deflated, big endian) is left to GDCM:
// run() says whether the whole file was walked.
class DicomWalk {
 public:
  explicit DicomWalk(const fs::path& file) : file_(file), size_(fs::file_size(file)), in_(file, std::ios::binary) {}

  bool run() {
    std::uintmax_t at = 132;
    // The meta header: explicit VR little endian, group 0002, first; its
    // length, when given (0002,0000), must be there too.
    if (group(at) == 0x0002 && number(at + 2, 2) == 0x0000 && 144 + number(at + 8, 4) > size_)
      fail("the meta header needs " + std::to_string(number(at + 8, 4)) + " bytes, the file has " +
           std::to_string(size_ - std::min<std::uintmax_t>(size_, 144)));
    while (at < size_ && group(at) == 0x0002) at = element(at);
    if (syntax_.empty()) fail("the meta header ends before its transfer syntax");
    if (at >= size_) fail("nothing follows the meta header");
    if (syntax_ == "1.2.840.10008.1.2") {
      explicitVr_ = false;
    } else if (syntax_ != "1.2.840.10008.1.2.1" && !isEncapsulated()) {
      return false;  // deflated or big endian: GDCM's alone
    }
    elements(at, false);
    return true;
  }

 private:
  static constexpr std::uint32_t kUndefined = 0xFFFFFFFFu;

  [[noreturn]] void fail(const std::string& what) const {
    throw Error(file_.string(), "a truncated DICOM file: " + what);
  }
  // Little-endian unsigned of n bytes at `at`; fails beyond the end.
  std::uint32_t number(std::uintmax_t at, int n) {
    if (at + n > size_) fail("an element is cut short at byte " + std::to_string(at));
    unsigned char bytes[4] = {};
    in_.seekg(static_cast<std::streamoff>(at));
    in_.read(reinterpret_cast<char*>(bytes), n);
    std::uint32_t v = 0;
    for (int i = n - 1; i >= 0; --i) v = (v << 8) | bytes[i];
    return v;
  }
  unsigned group(std::uintmax_t at) { return number(at, 2); }
  // JPEG, JPEG-LS, JPEG 2000, RLE: explicit VR little endian with encapsulated pixel data.
  bool isEncapsulated() const {
    return syntax_.rfind("1.2.840.10008.1.2.4.", 0) == 0 || syntax_ == "1.2.840.10008.1.2.5";
  }

  // Elements from `at` to the end of the file or, in an item of undefined
  // length, to its delimiter; returns the position after them.
  std::uintmax_t elements(std::uintmax_t at, bool inItem) {
    while (at < size_) {
      if (group(at) == 0xFFFE) {
        if (inItem && number(at + 2, 2) == 0xE00D) return at + 8;
        fail("a stray item delimiter at byte " + std::to_string(at));
      }
      at = element(at);
    }
    if (inItem) fail("an item of undefined length has no end");
    return at;
  }

  // One element at `at`; returns the position after it.
  std::uintmax_t element(std::uintmax_t at) {
    const unsigned tagGroup = group(at), tagElement = number(at + 2, 2);
    std::uintmax_t header = 8;
    std::uint32_t length = 0;
    const bool explicitVr = explicitVr_ || tagGroup == 0x0002;
    if (explicitVr) {
      const std::uint32_t vr = number(at + 4, 2);
      const std::string name{static_cast<char>(vr & 0xFF), static_cast<char>(vr >> 8)};
      static const std::set<std::string> longLength = {"OB", "OD", "OF", "OL", "OV", "OW", "SQ",
                                                       "SV", "UC", "UN", "UR", "UT", "UV"};
      if (longLength.count(name)) {
        length = number(at + 8, 4);
        header = 12;
      } else {
        length = number(at + 6, 2);
      }
    } else {
      length = number(at + 4, 4);
    }
    if (length == kUndefined) return sequence(at + header);  // a sequence, or encapsulated pixel data
    if (at + header + length > size_) {
      char name[16];
      std::snprintf(name, sizeof name, "(%04x,%04x)", tagGroup, tagElement);
      fail(std::string("element ") + name + " needs " + std::to_string(length) + " bytes, the file has " +
           std::to_string(size_ - at - header));
    }
    if (tagGroup == 0x0002 && tagElement == 0x0010) {  // the transfer syntax UID
      std::string value(length, '\0');
      in_.seekg(static_cast<std::streamoff>(at + header));
      in_.read(value.data(), static_cast<std::streamsize>(length));
      while (!value.empty() && (value.back() == '\0' || value.back() == ' ')) value.pop_back();
      syntax_ = value;
    }
    return at + header + length;
  }

  // Items (or pixel data fragments) up to the sequence delimiter.
  std::uintmax_t sequence(std::uintmax_t at) {
    while (true) {
      if (group(at) != 0xFFFE) fail("a sequence without its delimiter at byte " + std::to_string(at));
      const unsigned tagElement = number(at + 2, 2);
      const std::uint32_t length = number(at + 4, 4);
      if (tagElement == 0xE0DD) return at + 8;
      if (tagElement != 0xE000) fail("a sequence holds something other than items at byte " + std::to_string(at));
      if (length == kUndefined) {
        at = elements(at + 8, true);
      } else {
        if (at + 8 + length > size_)
          fail("an item needs " + std::to_string(length) + " bytes, the file has " + std::to_string(size_ - at - 8));
        at += 8 + length;
      }
    }
  }

  fs::path file_;
  std::uintmax_t size_;
  std::ifstream in_;
  bool explicitVr_ = true;
  std::string syntax_;
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
    if (entry.is_regular_file() && isDicomFile(entry.path()))
      files.push_back({entry.path(), fs::weakly_canonical(entry.path()), DicomWalk(entry.path()).run()});
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

}  // namespace

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
