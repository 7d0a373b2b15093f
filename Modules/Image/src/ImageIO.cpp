#include "dynsub/ImageIO.h"

#include <filesystem>

#include "BridgeGeometry.h"
#include "dynsub/AtomicOutput.h"
#include "dynsub/Error.h"
#include "dynsub/FileNames.h"

namespace dynsub {

Volume readVolume(const std::string& path) {
  std::error_code ignored;
  if (!std::filesystem::exists(path, ignored)) throw Error(path, "no such file or directory");
  itkbridge::Geometry raw;
  Volume volume;
  itkbridge::readImage(path, raw, volume.voxels);
  volume.geometry = fromBridge(raw);
  for (int a = 0; a < 3; ++a)
    if (volume.geometry.size[a] < 2)
      throw Error(path, "not a 3D image (" + std::to_string(volume.geometry.size[a]) + " voxel(s) along axis " +
                            std::to_string(a) + ")");
  if (!(std::abs(volume.geometry.direction.determinant()) > 1e-6)) throw Error(path, "singular direction matrix");
  if (!(volume.geometry.spacing.minCoeff() > 0)) throw Error(path, "spacing must be positive");
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

}  // namespace dynsub
