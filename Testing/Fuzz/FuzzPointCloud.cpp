// Point clouds: .xyz, .csv and VTK XML .vtp (readPointCloud), then the checks
// range fitting makes before using them (checkPointCloud).
#include <algorithm>

#include "FuzzInput.h"
#include "dynsub/Error.h"
#include "dynsub/PointCloudIO.h"
#include "dynsub/InitialModels.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace dynsub::fuzz;
  const std::uint8_t* lineEnd = std::find(data, data + size, '\n');
  const bool commas = std::find(data, lineEnd, ',') != lineEnd || std::find(data, lineEnd, ';') != lineEnd;
  const std::string extension = startsWith(data, size, "<") ? ".vtp" : commas ? ".csv" : ".xyz";
  const InputFile input(data, size, extension);
  try {
    const dynsub::MatrixX3 points = dynsub::readPointCloud(input.path()).points;
    dynsub::checkPointCloud(points, input.path());
    requireFinite(points);
  } catch (const dynsub::Error& e) {
    refused(e);
  }
  return 0;
}
