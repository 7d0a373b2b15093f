// Sculpting scripts (SculptScript.h): read and checked whole, before any
// action runs.
#include "FuzzInput.h"
#include "dynsub/Error.h"
#include "dynsub/SculptScript.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace dynsub::fuzz;
  const InputFile input(data, size, ".sculpt");
  try {
    dynsub::readSculptScript(input.path());
  } catch (const dynsub::Error& e) {
    refused(e);
  }
  return 0;
}
