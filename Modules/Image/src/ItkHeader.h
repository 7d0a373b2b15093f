#pragma once
// Private to the Image module's ITK bridge (ItkBridge.h): the check of an
// image file's header that ItkBridge.cpp and ItkDicom.cpp make before ITK
// reads its voxels.
#include <cstdint>
#include <sstream>
#include <string>

#include <itkImageIOBase.h>

#include "FileChecks.h"
#include "dynsub/Error.h"
#include "dynsub/TextFields.h"

namespace dynsub::itkbridge {

// An ITK exception's description as a reason a person can read: without the
// "itk::ERROR: NrrdImageIO(0x55...): Read: Error reading FILE:" preamble, and
// of a reading library's chain of "[nrrd] function: trouble reading" lines,
// the lines that say what is wrong ("couldn't open \"x.raw\" for reading"),
// joined by "; ".
inline std::string readableItkMessage(const std::string& description) {
  std::istringstream lines(description);
  std::string line, reasons;
  bool first = true;
  while (std::getline(lines, line)) {
    if (first) {
      first = false;
      // "itk::ERROR: NrrdImageIO(0x55...): " goes; what follows stays unless
      // it only announces the lines after it ("Read: Error reading x.nrrd:").
      line = afterObjectAddress(line);
      if (!line.empty() && line.back() == ':') continue;
    }
    // "[nrrd] _nrrdEncodingRaw_read: fread got only ..." -> "fread got only ..."
    if (!line.empty() && line[0] == '[') {
      const auto tag = line.find("] ");
      const auto colon = tag == std::string::npos ? std::string::npos : line.find(": ", tag);
      line = colon == std::string::npos ? std::string() : line.substr(colon + 2);
    }
    while (!line.empty() && (line.back() == ' ' || line.back() == ':')) line.pop_back();
    if (line.empty() || line == "trouble" || line.rfind("trouble reading", 0) == 0) continue;
    reasons += (reasons.empty() ? "" : "; ") + line;
  }
  return reasons.empty() ? description : reasons;
}

// After the project's own checks of the file (FileChecks.h), made by
// readVolume before it calls a library's readImage: `io` reads the header of
// `path`; an image too large for memory is refused before it is allocated,
// and one of more than three dimensions or of several values per voxel
// before ITK would make one 3D scalar image of it (readVolume refuses fewer
// than three).
inline void inspectHeader(const std::string& path, itk::ImageIOBase& io) {
  io.SetFileName(path);
  io.ReadImageInformation();
  std::uintmax_t voxels = 1;
  for (unsigned a = 0; a < io.GetNumberOfDimensions(); ++a) {
    const std::uintmax_t size = io.GetDimensions(a);
    if (size != 0 && voxels > UINTMAX_MAX / size) throw Error(path, "an image size that does not fit in 64 bits");
    voxels *= size;
  }
  filechecks::requireMemoryFor(path, voxels);
  // ITK reads the first volume of a series of them (a 4D image) into a 3D
  // image without a word.
  std::string sizes;
  bool beyond3D = false;
  for (unsigned a = 0; a < io.GetNumberOfDimensions(); ++a) {
    sizes += (a ? " x " : "") + std::to_string(io.GetDimensions(a));
    beyond3D = beyond3D || (a >= 3 && io.GetDimensions(a) > 1);
  }
  if (beyond3D)
    throw Error(path, "a " + std::to_string(io.GetNumberOfDimensions()) + "D image (" + sizes +
                          " voxels); DynSub reads 3D images: save the volume to segment as an image of its own");
  // ITK would turn a vector or colour voxel into one value (a luminance, or
  // the first component) without a word.
  const unsigned components = io.GetNumberOfComponents();
  if (components > 1) {
    throw Error(path, "an image of " + std::to_string(components) + " values per voxel (" +
                          itk::ImageIOBase::GetPixelTypeAsString(io.GetPixelType()) +
                          "); DynSub reads scalar images: save the channel to segment as an image of its own");
  }
}

}  // namespace dynsub::itkbridge
