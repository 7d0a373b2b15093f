#pragma once
// Private to the Image module: the only door to ITK. Its interface uses plain
// arrays, not Eigen, because ITK 5.2 bundles its own Eigen (3.3), whose
// headers cannot share a translation unit with the Eigen 3.4 the rest of
// DynSub uses, and whose inline functions must not meet Eigen 3.4's at link
// time. So ITK is included by ItkBridge.cpp and ItkDicom.cpp alone, which make
// a shared library of their own (libDynSubItkBridge.so) that exports these
// functions and nothing else.
#include <array>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#define DYNSUB_ITK_BRIDGE_API __attribute__((visibility("default")))

namespace dynsub::itkbridge {

struct Geometry {
  std::array<int, 3> size{};
  std::array<double, 3> spacing{};
  std::array<double, 3> origin{};
  std::array<double, 9> direction{};  // row-major, columns are the index axes
};

// A file in a format ITK reads without GDCM (NIfTI, NRRD, MetaImage), as
// float. Throws dynsub::Error naming the path. A file's own checks
// (FileChecks.h: checkImageHeader) are the caller's: its header's before,
// its data's before or beside.
DYNSUB_ITK_BRIDGE_API void readImage(const std::string& path, Geometry& geometry, std::vector<float>& voxels);

// A directory holding one DICOM series, or one DICOM file (FileChecks.h:
// isDicomFile), as float, through GDCM. Throws dynsub::Error naming the path.
DYNSUB_ITK_BRIDGE_API void readDicom(const std::string& path, Geometry& geometry, std::vector<float>& voxels);

// An 8-bit labelmap, compressed when the format allows; throws dynsub::Error.
// `fields` are written as the file's key/value pairs where the format has
// them (NRRD's "key:=value" lines).
DYNSUB_ITK_BRIDGE_API void writeLabels(const Geometry& geometry, const std::vector<std::uint8_t>& voxels,
                                       const std::string& path,
                                       const std::vector<std::pair<std::string, std::string>>& fields = {});

// A float image (`labels` false) or a label image of 16-bit signed integers
// (`labels` true, values rounded), compressed when the format allows;
// throws dynsub::Error.
DYNSUB_ITK_BRIDGE_API void writeImage(const Geometry& geometry, const std::vector<float>& voxels, bool labels,
                                      const std::string& path);

// The image smoothed by a Gaussian of sigma mm (Deriche's recursive filters).
DYNSUB_ITK_BRIDGE_API std::vector<float> recursiveGaussian(const Geometry& geometry, const std::vector<float>& voxels,
                                                           double sigma);

// Gradient (physical LPS axes, per mm) of the image smoothed by a Gaussian of
// sigma mm, with Deriche's recursive filters; three components per voxel.
DYNSUB_ITK_BRIDGE_API std::vector<float> recursiveGaussianGradient(const Geometry& geometry,
                                                                   const std::vector<float>& voxels, double sigma);

// Euclidean distance (mm) from every voxel centre to the nearest non-zero
// voxel (ITK's Maurer transform): the oracle DistanceUnitTests holds
// distanceTo (ImageFilters.h) to; the project itself uses its own.
DYNSUB_ITK_BRIDGE_API std::vector<float> distanceMap(const Geometry& geometry, const std::vector<std::uint8_t>& mask);

}  // namespace dynsub::itkbridge
