// The gzip check made before ITK reads a .nii.gz (FileChecks.h: inflateGzipFile).
#include "FileChecks.h"
#include "FuzzInput.h"
#include "dynsub/Error.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace dynsub::fuzz;
  const InputFile input(data, size, ".nii.gz");
  try {
    dynsub::filechecks::inflateGzipFile(input.path(), 1 << 20);
  } catch (const dynsub::Error& e) {
    refused(e);
  }
  return 0;
}
