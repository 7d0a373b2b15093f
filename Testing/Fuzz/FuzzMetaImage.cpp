// MetaImage files (.mha: header and data in one file): the check made before
// ITK reads them (FileChecks.h: checkMetaImageFile).
#include "FuzzImageFile.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  dynsub::fuzz::checkImageFile(data, size, ".mha", dynsub::filechecks::checkMetaImageFile);
  return 0;
}
