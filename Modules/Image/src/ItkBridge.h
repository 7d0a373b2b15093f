#pragma once
// Private to the Image module: the only door to ITK. Its interface uses plain
// arrays, not Eigen, because ITK 5.2 bundles its own Eigen (3.3) whose headers
// cannot share a translation unit with the Eigen 3.4 the rest of DynSub uses;
// so ITK is included by ItkBridge.cpp alone.
//
// ItkBridge.cpp is a library of its own, libDynSubItkBridge.so in the build's
// lib/ directory, opened at the first call of functions() (ItkBridgeLoader.cpp).
// A program that never reads, writes or filters an image (`dynsub fit`,
// `deform`, `limit`) then starts without ITK's libraries. DICOM is read by a
// third library, libDynSubItkDicom.so (ItkDicom.cpp, dicomFunctions()): GDCM's
// libraries and the building of its DICOM dictionary took 40-50 ms of the
// 50-65 ms that opening one library for both took, and a NIfTI file, the
// common case, needs none of it (Documentation/Performance.md).
#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace dynsub::itkbridge {

struct Geometry {
  std::array<int, 3> size{};
  std::array<double, 3> spacing{};
  std::array<double, 3> origin{};
  std::array<double, 9> direction{};  // row-major, columns are the index axes
};

// What ITK does for DynSub, as function pointers: ItkBridge.cpp fills them in
// the library, which exports them through one C symbol (kFunctionsSymbol).
struct Functions {
  // A file in a format ITK reads without GDCM (NIfTI, NRRD, MetaImage), as
  // float. Throws dynsub::Error naming the path. A file's own checks
  // (FileChecks.h: checkImageFile) are the caller's, made before.
  void (*readImage)(const std::string& path, Geometry& geometry, std::vector<float>& voxels);
  // The geometry readImage would give a file, from its header alone; false
  // when ITK does not see a 3D image of one component (readImage must then
  // read it). Throws dynsub::Error naming the path.
  bool (*readGeometry)(const std::string& path, Geometry& geometry);
  // An 8-bit labelmap, compressed when the format allows; throws dynsub::Error.
  void (*writeLabels)(const Geometry& geometry, const std::vector<std::uint8_t>& voxels, const std::string& path);
  // Gradient (physical LPS axes, per mm) of the image smoothed by a Gaussian of
  // sigma mm, with Deriche's recursive filters; three components per voxel.
  std::vector<float> (*recursiveGaussianGradient)(const Geometry& geometry, const std::vector<float>& voxels,
                                                  double sigma);
  // Euclidean distance (mm) from every voxel centre to the nearest non-zero
  // voxel (ITK's Maurer transform): the oracle DistanceUnitTests holds
  // distanceTo (ImageFilters.h) to; the project itself uses its own.
  std::vector<float> (*distanceMap)(const Geometry& geometry, const std::vector<std::uint8_t>& mask);
};
inline constexpr const char* kFunctionsSymbol = "dynsubItkBridgeFunctions";

// What ITK and GDCM do for DICOM, in libDynSubItkDicom.so.
struct DicomFunctions {
  // A directory holding one DICOM series, or one DICOM file (FileChecks.h:
  // isDicomFile), as float. Throws dynsub::Error naming the path.
  void (*readImage)(const std::string& path, Geometry& geometry, std::vector<float>& voxels);
};
inline constexpr const char* kDicomFunctionsSymbol = "dynsubItkDicomFunctions";

// Each library's functions, loaded at the first call (thread-safe). Throws
// dynsub::Error when the library cannot be opened.
const Functions& functions();
const DicomFunctions& dicomFunctions();

}  // namespace dynsub::itkbridge
