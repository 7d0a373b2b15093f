// DICOM read through ITK and GDCM, for the ITK bridge (ItkBridge.h).
#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <iostream>
#include <sstream>
#include <vector>

#include <gdcmReader.h>
#include <gdcmScanner.h>
#include <gdcmTrace.h>

#include <itkGDCMImageIO.h>
#include <itkGDCMSeriesFileNames.h>
#include <itkImageFileReader.h>
#include <itkImageSeriesReader.h>
#include <itkMetaDataObject.h>

#include "FileChecks.h"
#include "ItkBridge.h"
#include "ItkHeader.h"
#include "ItkImages.h"
#include "dynsub/Error.h"
#include "dynsub/TextFields.h"

namespace dynsub::itkbridge {
namespace {

namespace fs = std::filesystem;

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

// GDCM's warnings and errors held for a scope instead of printed: to read
// (a slice cut short: "Incomplete Pixel Data"), or to drop where the checks
// here report what they say (a slice position that is not unique) as errors
// naming the files. `warningsOn`: GDCM's warnings, which ITK turns off, are on
// for the scope.
class GdcmMessagesHeld {
 public:
  explicit GdcmMessagesHeld(bool warningsOn = false)
      : warnings_(gdcm::Trace::GetWarningFlag()), errors_(gdcm::Trace::GetErrorFlag()) {
    if (warningsOn) gdcm::Trace::WarningOn();
    gdcm::Trace::SetWarningStream(held_);
    gdcm::Trace::SetErrorStream(held_);
  }
  ~GdcmMessagesHeld() {
    gdcm::Trace::SetWarningStream(std::cerr);
    gdcm::Trace::SetErrorStream(std::cerr);
    gdcm::Trace::SetWarning(warnings_);
    gdcm::Trace::SetError(errors_);
  }
  GdcmMessagesHeld(const GdcmMessagesHeld&) = delete;
  GdcmMessagesHeld& operator=(const GdcmMessagesHeld&) = delete;
  std::string text() const { return held_.str(); }

 private:
  std::ostringstream held_;
  bool warnings_, errors_;
};

// The numbers of a DICOM multi-valued string ("0.5\\0.5"); empty when it
// holds none or something else.
std::vector<double> dicomNumbers(const char* text) {
  std::vector<double> numbers;
  if (!text || !*text) return numbers;
  for (const std::string& item : splitItems(text, '\\')) {
    double number = 0;
    if (!parseNumber(trimmed(item), number) || !std::isfinite(number)) return {};
    numbers.push_back(number);
  }
  return numbers;
}

bool near(const std::vector<double>& a, const std::vector<double>& b, double tolerance) {
  if (a.size() != b.size()) return false;
  for (std::size_t i = 0; i < a.size(); ++i)
    if (std::abs(a[i] - b[i]) > tolerance) return false;
  return true;
}

// ITK places a series' slices by each one's position and the first one's
// orientation and pixel spacing: a slice without a position would be placed
// by guesswork, one of another orientation or spacing read as if it had the
// first one's, and two at one position (a repeated acquisition, or echoes
// left in one series) read as a slice of its own each. Each slice must state
// a position of its own and the first one's orientation and spacing.
void requireOneSliceGeometry(const std::vector<std::string>& files) {
  if (files.size() < 2) return;
  const gdcm::Tag position(0x0020, 0x0032), orientation(0x0020, 0x0037), spacing(0x0028, 0x0030),
      frames(0x0028, 0x0008);
  gdcm::Scanner scanner;
  scanner.AddTag(frames);
  scanner.AddTag(position);
  scanner.AddTag(orientation);
  scanner.AddTag(spacing);
  if (!scanner.Scan(files)) throw Error(files.front(), "cannot read the headers of the DICOM series' slices");
  const std::string& first = files.front();
  const std::vector<double> firstOrientation = dicomNumbers(scanner.GetValue(first.c_str(), orientation)),
                            firstSpacing = dicomNumbers(scanner.GetValue(first.c_str(), spacing));
  std::vector<std::pair<std::vector<double>, std::string>> placed;
  for (const std::string& file : files) {
    const std::vector<double> at = dicomNumbers(scanner.GetValue(file.c_str(), position));
    const std::vector<double> frameCount = dicomNumbers(scanner.GetValue(file.c_str(), frames));
    if (!frameCount.empty() && frameCount.front() > 1)
      throw Error(file, "a file of " + std::to_string(static_cast<long long>(frameCount.front())) +
                            " frames in a series of several files: a multi-frame file holds a volume of its own; "
                            "give it alone");
    if (at.size() != 3)
      throw Error(file,
                  "a slice of the DICOM series states no Image Position (Patient) (0020,0032): where it lies "
                  "in the volume is unknown");
    if (!near(dicomNumbers(scanner.GetValue(file.c_str(), orientation)), firstOrientation, 1e-4))
      throw Error(file, "a slice of the DICOM series has another Image Orientation (Patient) (0020,0037) than " +
                            first + ": slices of one volume share one orientation");
    const std::vector<double> pixels = dicomNumbers(scanner.GetValue(file.c_str(), spacing));
    if (!near(pixels, firstSpacing, 1e-4 * (firstSpacing.empty() ? 1.0 : firstSpacing.front())))
      throw Error(file, "a slice of the DICOM series has another Pixel Spacing (0028,0030) than " + first +
                            ": slices of one volume share one spacing");
    for (const auto& [other, otherFile] : placed)
      if (near(at, other, 1e-3))
        throw Error(file, "two slices of the DICOM series lie at one position (0020,0032), this one and " + otherFile +
                              ": a repeated acquisition, or several echoes or phases in one series; give a folder of "
                              "one volume's slices");
    placed.emplace_back(at, file);
  }
}

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
    const GdcmMessagesHeld held(true);
    gdcm::Reader reader;
    reader.SetFileName(file.c_str());
    if (!reader.Read() || held.text().find("Incomplete Pixel Data") != std::string::npos)
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

FloatImage::Pointer readSeries(const std::string& directory) {
  const std::vector<DicomFile> dicomFiles = walkDicomFiles(directory);
  // ITK's warnings (no series, uneven slices) would only repeat, less
  // clearly, what the checks here report as errors.
  const WarningsOff quiet;
  auto names = itk::GDCMSeriesFileNames::New();
  std::vector<std::string> files;
  {
    const GdcmMessagesHeld held;
    names->SetUseSeriesDetails(true);
    names->SetDirectory(directory);
    const auto series = names->GetSeriesUIDs();
    if (series.empty()) {
      bool folders = false;
      for (const auto& entry : fs::directory_iterator(directory)) folders = folders || entry.is_directory();
      throw Error(directory, std::string("directory holds no DICOM series") +
                                 (folders ? " (its subfolders are not searched: give the folder that holds the "
                                            "series' files)"
                                          : ""));
    }
    if (series.size() > 1) {
      // Each named by one of its files, so that the user can tell them apart.
      std::string listed;
      for (std::size_t s = 0; s < series.size() && s < 4; ++s) {
        const std::vector<std::string> its = names->GetFileNames(series[s]);
        listed += std::string(listed.empty() ? "" : ", ") + "that of " +
                  (its.empty() ? series[s] : fs::path(its.front()).filename().string()) + " (" +
                  std::to_string(its.size()) + (its.size() == 1 ? " file)" : " files)");
      }
      throw Error(directory, "directory holds " + std::to_string(series.size()) + " DICOM series (" + listed +
                                 (series.size() > 4 ? ", ..." : "") + "); give a folder of one series");
    }
    files = names->GetFileNames(series.front());
  }
  requireWholeSeries(files, dicomFiles);
  requireOneSliceGeometry(files);
  // A colour or vector series is refused as such a file is (the series
  // reader would make one value of each voxel's several).
  auto header = itk::GDCMImageIO::New();
  inspectHeader(files.front(), *header);
  auto reader = itk::ImageSeriesReader<FloatImage>::New();
  reader->SetImageIO(itk::GDCMImageIO::New());
  reader->SetFileNames(files);
  reader->Update();
  FloatImage::Pointer image = reader->GetOutput();
  requireEvenSlices(directory, *image);
  return image;
}

// One file (a multi-frame image holds a volume): checked as a series of one.
FloatImage::Pointer readFile(const std::string& path) {
  const DicomFile file{path, fs::weakly_canonical(path), filechecks::walkDicomFile(path)};
  requireWholeSeries({path}, {file});
  auto io = itk::GDCMImageIO::New();
  inspectHeader(path, *io);
  auto reader = itk::ImageFileReader<FloatImage>::New();
  reader->SetImageIO(io);
  reader->SetFileName(path);
  reader->Update();
  return reader->GetOutput();
}

}  // namespace

void readDicom(const std::string& path, Geometry& geometry, std::vector<float>& voxels) {
  try {
    std::error_code ignored;
    const FloatImage::Pointer image = fs::is_directory(path, ignored) ? readSeries(path) : readFile(path);
    geometry = geometryOf(image);
    const float* buffer = image->GetBufferPointer();
    voxels.assign(buffer, buffer + countOf(geometry));
  } catch (const itk::ExceptionObject& e) {
    throw Error(path, "cannot read image: " + readableItkMessage(e.GetDescription()));
  }
}

}  // namespace dynsub::itkbridge
