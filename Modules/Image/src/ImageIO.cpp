#include "dynsub/ImageIO.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <future>
#include <sstream>

#include "BridgeGeometry.h"
#include "FileChecks.h"
#include "NiftiLabelmap.h"
#include "dynsub/AtomicOutput.h"
#include "dynsub/Error.h"
#include "dynsub/FileNames.h"

namespace dynsub {

namespace {

// "(i, j, k)" of the voxel at `offset`, for messages.
std::string voxelText(const ImageGeometry& grid, long long offset) {
  const std::array<int, 3> v = grid.voxelAt(offset);
  return "(" + std::to_string(v[0]) + ", " + std::to_string(v[1]) + ", " + std::to_string(v[2]) + ")";
}

}  // namespace

Volume readVolume(const std::string& path) {
  requireExisting(path);
  std::error_code ignored;
  Volume volume;
  itkbridge::Geometry raw;
  const bool directory = std::filesystem::is_directory(path, ignored);
  const bool dicomFile = !directory && !filechecks::isNiftiName(path) && filechecks::isDicomFile(path);
  if (directory || dicomFile) {
    itkbridge::readDicom(path, raw, volume.voxels);
  } else {
    // The header's checks guard the reader's allocation. The data's (a
    // .nii.gz inflated whole, float voxels scanned) take about as long as
    // ITK's read, so they run beside it, on the second core.
    const filechecks::DataCheck checkData = filechecks::checkImageHeader(path);
    std::future<void> dataChecked = std::async(std::launch::async, checkData);
    try {
      itkbridge::readImage(path, raw, volume.voxels);
    } catch (...) {
      dataChecked.get();  // the check's error, when it has one, says what is wrong with the file
      throw;
    }
    dataChecked.get();
  }
  volume.geometry = fromBridge(raw);
  for (int a = 0; a < 3; ++a)
    if (volume.geometry.size[a] < 2) {
      std::string hint;
      // A DICOM series stores one slice a file: the series is its folder.
      if (dicomFile && a == 2) {
        const std::filesystem::path absolute = std::filesystem::absolute(path, ignored);
        hint = ": a DICOM file holds one slice of its series; give the series' folder (" +
               (absolute.empty() ? std::filesystem::path(path) : absolute).parent_path().string() + ")";
      }
      throw Error(path, "not a 3D image (" + std::to_string(volume.geometry.size[a]) + " voxel(s) along axis " +
                            std::to_string(a) + ")" + hint);
    }
  const ImageGeometry& g = volume.geometry;
  if (!g.origin.allFinite()) throw Error(path, "the origin is not finite");
  // Options, tolerances and reports are in mm, chosen for voxels of tenths of
  // a mm to a few mm: a spacing far outside that is a broken header (or a
  // file in other units) that would give meaningless results.
  if (!(g.spacing.minCoeff() >= kSmallestSpacing && g.spacing.maxCoeff() <= kLargestSpacing)) {
    std::ostringstream message;
    message << "voxel spacing " << g.spacing.x() << " x " << g.spacing.y() << " x " << g.spacing.z() << " mm ";
    if (!(g.spacing.minCoeff() > 0))
      message << "is not positive";
    else
      message << "is outside the " << kSmallestSpacing << " to " << kLargestSpacing << " mm DynSub works with";
    throw Error(path, message.str());
  }
  if (!g.direction.allFinite() || !(std::abs(g.direction.determinant()) > 1e-6))
    throw Error(path, "singular direction matrix");
  // Axes at right angles, of unit length, as ITK's filters and every output
  // format's header take them: a sheared or scaled matrix (as a header may
  // hold one) would place the results elsewhere in each viewer.
  const double skew = (g.direction.transpose() * g.direction - Matrix3::Identity()).cwiseAbs().maxCoeff();
  if (skew > 1e-3) {
    std::ostringstream message;
    message << "the direction matrix is not orthonormal (its axes' dot products and lengths are off by up to " << skew
            << "): DynSub needs axes at right angles, of unit length; resample the image onto such a grid";
    throw Error(path, message.str());
  }
  // NaN or infinite intensities would spread through the smoothing into every
  // force near them.
  const auto bad =
      std::find_if(volume.voxels.begin(), volume.voxels.end(), [](float v) { return !std::isfinite(v); });
  if (bad != volume.voxels.end()) {
    const long long count = std::count_if(bad, volume.voxels.end(), [](float v) { return !std::isfinite(v); });
    throw Error(path, std::to_string(count) + " voxel(s) are NaN or infinite, the first at index " +
                          voxelText(g, bad - volume.voxels.begin()) + "; intensities must be finite");
  }
  return volume;
}

Volume readLabelMap(const std::string& path) {
  Volume labels = readVolume(path);
  const auto bad = std::find_if(labels.voxels.begin(), labels.voxels.end(), [](float v) { return v != std::round(v); });
  if (bad != labels.voxels.end())
    throw Error(path, "not a label map: voxel " + voxelText(labels.geometry, bad - labels.voxels.begin()) + " holds " +
                          std::to_string(*bad) +
                          ", and labels are whole numbers (was it resampled with interpolation?)");
  return labels;
}

void writeMask(const Mask& mask, const std::string& path, std::uint8_t label) {
  // The file is written under a temporary name and renamed when complete; a
  // header that names a separate data file would name the temporary one.
  const std::string extension = lowerCaseExtension(path);
  if (extension == ".mhd" || extension == ".nhdr" || extension == ".hdr")
    throw Error(path, "a header with a separate data file is not written; use .nii.gz, .nii, .nrrd or .mha");
  if (label == 0) throw Error(path, "the structure's label value must be 1-255 (0 is the background)");
  requireWritableDirectoryFor(path);
  if (filechecks::isNiftiName(path)) {
    writeNiftiLabelmap(mask, label, path);
    return;
  }
  AtomicOutput output(path);
  if (label == 1) {
    itkbridge::writeLabels(toBridge(mask.geometry), mask.voxels, output.temporaryPath());
  } else {
    std::vector<std::uint8_t> labels(mask.voxels.size());
    for (std::size_t i = 0; i < labels.size(); ++i) labels[i] = mask.voxels[i] ? label : 0;
    itkbridge::writeLabels(toBridge(mask.geometry), labels, output.temporaryPath());
  }
  output.commit();
}

void writeVolume(const Volume& volume, const std::string& path, VoxelType type) {
  const std::string extension = lowerCaseExtension(path);
  if (extension == ".mhd" || extension == ".nhdr" || extension == ".hdr")
    throw Error(path, "a header with a separate data file is not written; use .nii.gz, .nii, .nrrd or .mha");
  if (type == VoxelType::Label16) {
    for (const float v : volume.voxels)
      if (!(v >= -32768.0f && v <= 32767.0f)) throw Error(path, "a label value outside -32768..32767: " + std::to_string(v));
  }
  requireWritableDirectoryFor(path);
  AtomicOutput output(path);
  itkbridge::writeImage(toBridge(volume.geometry), volume.voxels, type == VoxelType::Label16, output.temporaryPath());
  output.commit();
}

bool isSlicerSegmentationName(const std::string& path) {
  return lowerCaseExtension(path) == ".nrrd" &&
         lowerCaseExtension(std::filesystem::path(path).stem().string()) == ".seg";
}

namespace {

// Which segment each label value is (-1: none; 0 is the background), once
// the file's name and the segments are checked.
std::array<int, 256> checkSegmentation(const std::vector<SlicerSegment>& segments, const std::string& path) {
  if (!isSlicerSegmentationName(path)) throw Error(path, "a 3D Slicer segmentation is written as .seg.nrrd");
  if (segments.empty()) throw Error(path, "a segmentation needs at least one segment");
  std::array<int, 256> segmentOf;
  segmentOf.fill(-1);
  for (std::size_t s = 0; s < segments.size(); ++s) {
    const SlicerSegment& segment = segments[s];
    if (segment.label < 1 || segment.label > 255)
      throw Error(path, "segment '" + segment.name + "': label " + std::to_string(segment.label) + " is outside 1-255");
    if (segmentOf[segment.label] >= 0)
      throw Error(path, "label " + std::to_string(segment.label) + " is given to two segments");
    segmentOf[segment.label] = static_cast<int>(s);
    // A NRRD key/value pair ends at the line's end.
    if (segment.name.empty() ||
        std::any_of(segment.name.begin(), segment.name.end(), [](unsigned char c) { return c < 0x20 || c == 0x7f; }))
      throw Error(path, "segment " + std::to_string(s + 1) + ": a name must be non-empty, without control characters");
    for (const double c : segment.color)
      if (!(c >= 0 && c <= 1)) throw Error(path, "segment '" + segment.name + "': a colour component outside 0-1");
  }
  return segmentOf;
}

// The checked segments' labels on `g`'s grid, with the fields Slicer reads.
void writeSegmentationFile(const ImageGeometry& g, const std::vector<std::uint8_t>& voxels,
                           const std::vector<SlicerSegment>& segments, const std::string& path) {
  // Every segment of a layer gives the layer's extent: Slicer's reader crops
  // the layer to the extent of its first segment. The whole grid keeps every
  // segment's voxels, an empty one's too.
  const std::string extent = "0 " + std::to_string(g.size[0] - 1) + " 0 " + std::to_string(g.size[1] - 1) + " 0 " +
                             std::to_string(g.size[2] - 1);
  std::vector<std::pair<std::string, std::string>> fields = {
      {"Segmentation_SourceRepresentation", "Binary labelmap"},
      // The same under its earlier name, which Slicer still writes.
      {"Segmentation_MasterRepresentation", "Binary labelmap"},
      // Slicer makes the closed surfaces on loading, so that the segments
      // show in 3D at once.
      {"Segmentation_ContainedRepresentationNames", "Binary labelmap|Closed surface|"},
      {"Segmentation_ReferenceImageExtentOffset", "0 0 0"}};
  for (std::size_t s = 0; s < segments.size(); ++s) {
    const SlicerSegment& segment = segments[s];
    const std::string key = "Segment" + std::to_string(s) + "_";
    std::ostringstream color;
    color << segment.color[0] << ' ' << segment.color[1] << ' ' << segment.color[2];
    fields.insert(fields.end(), {{key + "ID", "Segment_" + std::to_string(segment.label)},
                                 {key + "Name", segment.name},
                                 {key + "NameAutoGenerated", "0"},
                                 {key + "Color", color.str()},
                                 {key + "ColorAutoGenerated", "0"},
                                 {key + "LabelValue", std::to_string(segment.label)},
                                 {key + "Layer", "0"},
                                 {key + "Extent", extent},
                                 {key + "Tags", "|"}});
  }
  requireWritableDirectoryFor(path);
  AtomicOutput output(path);
  itkbridge::writeLabels(toBridge(g), voxels, output.temporaryPath(), fields);
  output.commit();
}

}  // namespace

void writeSlicerSegmentation(const Volume& labels, const std::vector<SlicerSegment>& segments,
                             const std::string& path) {
  const std::array<int, 256> segmentOf = checkSegmentation(segments, path);
  std::vector<std::uint8_t> voxels(labels.voxels.size());
  for (std::size_t v = 0; v < voxels.size(); ++v) {
    const float value = labels.voxels[v];
    if (value == 0) continue;
    if (!(value >= 1 && value <= 255 && value == std::floor(value)) || segmentOf[static_cast<int>(value)] < 0)
      throw Error(path, "voxel value " + std::to_string(value) + " is no segment's label");
    voxels[v] = static_cast<std::uint8_t>(value);
  }
  writeSegmentationFile(labels.geometry, voxels, segments, path);
}

void writeSlicerSegmentation(const Mask& mask, const SlicerSegment& segment, const std::string& path) {
  checkSegmentation({segment}, path);
  std::vector<std::uint8_t> voxels(mask.voxels.size());
  const auto label = static_cast<std::uint8_t>(segment.label);
  for (std::size_t v = 0; v < voxels.size(); ++v) voxels[v] = mask.voxels[v] ? label : 0;
  writeSegmentationFile(mask.geometry, voxels, {segment}, path);
}

}  // namespace dynsub
