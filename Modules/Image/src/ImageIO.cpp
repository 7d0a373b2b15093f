#include "dynsub/ImageIO.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <sstream>

#include "BridgeGeometry.h"
#include "FileChecks.h"
#include "NiftiLabelmap.h"
#include "dynsub/AtomicOutput.h"
#include "dynsub/Error.h"
#include "dynsub/FileNames.h"

namespace dynsub {

Volume readVolume(const std::string& path) {
  requireExisting(path);
  std::error_code ignored;
  Volume volume;
  itkbridge::Geometry raw;
  if (std::filesystem::is_directory(path, ignored) || (!filechecks::isNiftiName(path) && filechecks::isDicomFile(path))) {
    itkbridge::readDicom(path, raw, volume.voxels);
  } else {
    filechecks::checkImageFile(path);
    itkbridge::readImage(path, raw, volume.voxels);
  }
  volume.geometry = fromBridge(raw);
  for (int a = 0; a < 3; ++a)
    if (volume.geometry.size[a] < 2)
      throw Error(path, "not a 3D image (" + std::to_string(volume.geometry.size[a]) + " voxel(s) along axis " +
                            std::to_string(a) + ")");
  const ImageGeometry& g = volume.geometry;
  if (!g.direction.allFinite() || !(std::abs(g.direction.determinant()) > 1e-6))
    throw Error(path, "singular direction matrix");
  if (!g.origin.allFinite()) throw Error(path, "the origin is not finite");
  if (!(g.spacing.minCoeff() > 0)) throw Error(path, "spacing must be positive");
  // Options, tolerances and reports are in mm, chosen for voxels of tenths of
  // a mm to a few mm: a spacing far outside that is a broken header (or a
  // file in other units) that would give meaningless results.
  if (!(g.spacing.minCoeff() >= kSmallestSpacing && g.spacing.maxCoeff() <= kLargestSpacing)) {
    std::ostringstream message;
    message << "voxel spacing " << g.spacing.x() << " x " << g.spacing.y() << " x " << g.spacing.z()
            << " mm is outside the " << kSmallestSpacing << " to " << kLargestSpacing << " mm DynSub works with";
    throw Error(path, message.str());
  }
  // NaN or infinite intensities would spread through the smoothing into every
  // force near them.
  const auto bad =
      std::find_if(volume.voxels.begin(), volume.voxels.end(), [](float v) { return !std::isfinite(v); });
  if (bad != volume.voxels.end()) {
    const long long first = bad - volume.voxels.begin(), count = std::count_if(bad, volume.voxels.end(), [](float v) {
      return !std::isfinite(v);
    });
    const long long i = first % g.size[0], j = first / g.size[0] % g.size[1], k = first / g.size[0] / g.size[1];
    throw Error(path, std::to_string(count) + " voxel(s) are NaN or infinite, the first at index (" +
                          std::to_string(i) + ", " + std::to_string(j) + ", " + std::to_string(k) +
                          "); intensities must be finite");
  }
  return volume;
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

}  // namespace dynsub
