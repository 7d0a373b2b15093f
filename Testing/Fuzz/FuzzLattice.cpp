// Subdivision-solid control lattices (.lattice), read and checked (LatticeIO.h).
#include "FuzzInput.h"
#include "dynsub/Error.h"
#include "dynsub/LatticeIO.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace dynsub::fuzz;
  const InputFile input(data, size, ".lattice");
  try {
    requireFinite(dynsub::readLattice(input.path()).points());
  } catch (const dynsub::Error& e) {
    refused(e);
  }
  return 0;
}
