// Spring files of dynsub deform (SpringFile.h).
#include "FuzzInput.h"
#include "dynsub/Error.h"
#include "dynsub/SpringFile.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace dynsub::fuzz;
  const InputFile input(data, size, ".springs");
  try {
    const dynsub::SpringFile springs = dynsub::readSpringFile(input.path(), 10.0);
    requireFinite(springs.targets);
    requireFinite(springs.stiffness);
  } catch (const dynsub::Error& e) {
    refused(e);
  }
  return 0;
}
