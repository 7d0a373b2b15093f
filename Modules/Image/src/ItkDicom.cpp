// DICOM read through ITK and GDCM, for the ITK bridge (ItkBridge.h).
#include <algorithm>
#include <cctype>
#include <filesystem>
#include <iostream>
#include <sstream>
#include <vector>

#include <gdcmReader.h>
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

FloatImage::Pointer readSeries(const std::string& directory) {
  const std::vector<DicomFile> dicomFiles = walkDicomFiles(directory);
  // ITK's warnings (no series, uneven slices) would only repeat, less
  // clearly, what the checks here report as errors.
  const WarningsOff quiet;
  auto names = itk::GDCMSeriesFileNames::New();
  names->SetUseSeriesDetails(true);
  names->SetDirectory(directory);
  const auto series = names->GetSeriesUIDs();
  if (series.empty()) throw Error(directory, "directory holds no DICOM series");
  if (series.size() > 1)
    throw Error(directory, "directory holds " + std::to_string(series.size()) + " DICOM series; give one series");
  const std::vector<std::string> files = names->GetFileNames(series.front());
  requireWholeSeries(files, dicomFiles);
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
