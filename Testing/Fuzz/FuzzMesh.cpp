// Control meshes: OBJ, OFF and PLY (ASCII and binary), read and checked
// (readControlMesh: parsing, then every validity check of MeshCheck.h).
#include "FuzzInput.h"
#include "dynsub/Error.h"
#include "dynsub/MeshIO.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace dynsub::fuzz;
  const std::string extension = startsWith(data, size, "ply") ? ".ply" : startsWith(data, size, "OFF") ? ".off" : ".obj";
  const InputFile input(data, size, extension);
  try {
    const dynsub::ControlMesh mesh = dynsub::readControlMesh(input.path());
    requireFinite(mesh.points());
  } catch (const dynsub::Error& e) {
    refused(e);
  }
  return 0;
}
