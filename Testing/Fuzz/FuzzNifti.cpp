// NIfTI images (.nii, and .nii.gz when the input is gzip data): the checks
// made before ITK reads them (FileChecks.h: checkNiftiFile).
#include "FuzzImageFile.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const bool gzip = size >= 2 && data[0] == 0x1f && data[1] == 0x8b;
  dynsub::fuzz::checkImageFile(data, size, gzip ? ".nii.gz" : ".nii", [](const std::string& path) {
    dynsub::filechecks::checkNiftiFile(path);
  });
  return 0;
}
