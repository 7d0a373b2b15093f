#pragma once
// Private to the Image module: checks of image files that ITK and GDCM leave
// out, made before either reads the file. They read bytes only (no ITK), so
// they can be tested and fuzzed on their own (Testing/Fuzz).
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

namespace dynsub::filechecks {

// The number of bytes a gzip file inflates to, or at least `enough` when it
// inflates to that many or more (inflating stops there). Throws
// dynsub::Error when its stream is cut short or corrupt before that.
std::uintmax_t inflatedSize(const std::string& path, std::uintmax_t enough = UINTMAX_MAX);

// Throws dynsub::Error when an image of `voxels` voxels would not fit in this
// machine's memory as float (a corrupt or hostile header), before anything
// allocates it.
void requireMemoryFor(const std::string& path, std::uintmax_t voxels);

// A NIfTI file (.nii, or .nii.gz when `path` ends in .gz): its header is
// NIfTI-1 or NIfTI-2 in either byte order, its sizes and datatype possible,
// the image fits in memory, and its data (inflated) is all there. Throws
// dynsub::Error naming the file and the problem.
void checkNiftiFile(const std::string& path);

// checkNiftiFile's checks and, in the same pass over the data, the voxels as
// float, for a file ITK would read as it is stored and cast to float: NIfTI-1
// in one file (magic "n+1"), three dimensions, a datatype of 8 to 64 bit
// integers or floats, no intensity scaling (scl_slope 1, scl_inter 0) and a
// whole data offset. Returns false, with `voxels` untouched, after the same
// checks for any other NIfTI file (ITK reads those). Throws as checkNiftiFile
// does, and for NaN or infinite voxels (which ITK would turn into 0).
bool readNiftiVoxels(const std::string& path, std::vector<float>& voxels);

// A MetaImage file (.mha, .mhd): NDims, DimSize and ElementType are there and
// possible, the image fits in memory, and its data is all there, after the
// header (LOCAL) or in its data file, CompressedDataSize bytes when
// compressed. Throws dynsub::Error naming the file that falls short.
void checkMetaImageFile(const std::string& path);

// Whether the file's name says NIfTI: .nii or .nii.gz (any case).
bool isNiftiName(const std::string& path);

// The checks above that the file's name calls for: NIfTI for .nii and
// .nii.gz, MetaImage for .mha and .mhd; none for other names.
void checkImageFile(const std::string& path);

// Whether a file says it is DICOM: "DICM" after the 128-byte preamble.
bool isDicomFile(const std::filesystem::path& file);

// Walks the elements of a DICOM file, each of which must fit in the file.
// Returns true when the whole file was walked, false when its transfer
// syntax is one the walk leaves to GDCM (deflated, big endian). Throws
// dynsub::Error naming the file when it is truncated or its structure broken.
bool walkDicomFile(const std::filesystem::path& file);

}  // namespace dynsub::filechecks
