// Landmark files: 3D Slicer markups (.mrk.json), Slicer fiducial lists
// (.fcsv) and spreadsheets (.csv), by their first byte.
#include "FuzzInput.h"
#include "dynsub/Error.h"
#include "dynsub/Landmarks.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace dynsub::fuzz;
  const std::string extension = startsWith(data, size, "{") ? ".mrk.json" : startsWith(data, size, "#") ? ".fcsv" : ".csv";
  const InputFile input(data, size, extension);
  try {
    requireFinite(dynsub::landmarkPositions(dynsub::readLandmarks(input.path())));
  } catch (const dynsub::Error& e) {
    refused(e);
  }
  return 0;
}
