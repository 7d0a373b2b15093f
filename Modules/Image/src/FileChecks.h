#pragma once
// Private to the Image module: checks of image files that ITK and GDCM leave
// out, made before either reads the file. They read bytes only (no ITK), so
// they can be tested and fuzzed on their own (Testing/Fuzz). One source per
// format: NiftiCheck.cpp, MetaImageCheck.cpp, DicomCheck.cpp; what they
// share is in FileChecks.cpp.
#include <cstdint>
#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <vector>

namespace dynsub::filechecks {

// a * b, or nothing when the product does not fit in 64 bits.
inline std::optional<std::uintmax_t> checkedProduct(std::uintmax_t a, std::uintmax_t b) {
  std::uintmax_t result = 0;
  if (__builtin_mul_overflow(a, b, &result)) return std::nullopt;
  return result;
}

// The bytes a gzip file (from byte `start` on: a NRRD's data follows its
// header) inflates to, in one piece (libdeflate). `expected` is the size its
// contents announce; more than four times as much is refused rather than
// allocated. Throws dynsub::Error naming the file when its stream is cut
// short or corrupt.
std::vector<unsigned char> inflateGzipFile(const std::string& path, std::uintmax_t expected, std::uintmax_t start = 0);

// Throws dynsub::Error when an image of `voxels` voxels would not fit in this
// machine's memory as float (a corrupt or hostile header), before anything
// allocates it.
void requireMemoryFor(const std::string& path, std::uintmax_t voxels);

// A file's checks come in two parts: the header's, which must pass before a
// reader allocates what the header announces, and the data's (all there,
// finite), which read the whole file and so may run while a reader reads it.
// The header's part returns the data's (a no-op when there is none).
using DataCheck = std::function<void()>;

// The most a deflate stream inflates: 1032 bytes out per byte in.
constexpr std::uintmax_t kLargestDeflateRatio = 1032;

// A NIfTI file (.nii, or .nii.gz when `path` ends in .gz): its header is
// NIfTI-1 in either byte order (NIfTI-2 is named as what ITK 5.2 does not
// read), its sizes and datatype possible,
// the image fits in memory, and the file is large enough to hold (or, gzipped,
// to inflate to) the data announced; then (the DataCheck) its data (inflated) is
// all there, and its float voxels finite (ITK's reader would turn NaN and
// infinities into 0). Each throws dynsub::Error naming the file and the problem.
DataCheck checkNiftiHeader(const std::string& path);
inline void checkNiftiFile(const std::string& path) { checkNiftiHeader(path)(); }

// A MetaImage file (.mha, .mhd): NDims, DimSize and ElementType are there and
// possible, the image fits in memory, and its data is all there, after the
// header (LOCAL) or in its data file, CompressedDataSize bytes when
// compressed. Throws dynsub::Error naming the file that falls short.
void checkMetaImageFile(const std::string& path);

// A NRRD file (.nrrd) with its raw data after the header: the data is no
// longer than its sizes and type announce (ITK would read the first bytes
// as the image). Throws dynsub::Error naming the file; other encodings and
// detached data are left to ITK, which reports data that falls short.
void checkNrrdFile(const std::string& path);

// Whether the file's name says NIfTI: .nii or .nii.gz (any case).
bool isNiftiName(const std::string& path);

// The checks above that the file's name calls for: NIfTI for .nii and
// .nii.gz, MetaImage for .mha and .mhd (all of it in the header's part);
// none for other names.
DataCheck checkImageHeader(const std::string& path);

// Whether a file says it is DICOM: "DICM" after the 128-byte preamble.
bool isDicomFile(const std::filesystem::path& file);

// Walks the elements of a DICOM file, each of which must fit in the file.
// Returns true when the whole file was walked, false when its transfer
// syntax is one the walk leaves to GDCM (deflated, big endian). Throws
// dynsub::Error naming the file when it is truncated or its structure broken.
bool walkDicomFile(const std::filesystem::path& file);

}  // namespace dynsub::filechecks
