// The walk over a DICOM file's elements made before GDCM reads it
// (FileChecks.h: isDicomFile, walkDicomFile).
#include "FileChecks.h"
#include "FuzzInput.h"
#include "dynsub/Error.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace dynsub::fuzz;
  const InputFile input(data, size, ".dcm");
  try {
    if (dynsub::filechecks::isDicomFile(input.path())) dynsub::filechecks::walkDicomFile(input.path());
  } catch (const dynsub::Error& e) {
    refused(e);
  }
  return 0;
}
