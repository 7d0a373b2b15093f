#pragma once
// Reading volumes and writing labelmaps, in physical LPS mm with the file's
// origin, spacing and direction (NIfTI's RAS qform/sform is turned into LPS
// when reading and back when writing). ITK reads every image, after
// DynSub's checks of its file (truncation, sizes, NaN); NIfTI labelmaps are
// written by DynSub, .nrrd and .mha ones by ITK.
//
// Readable: NIfTI (.nii, .nii.gz), NRRD (.nrrd, .nhdr), MetaImage (.mha,
// .mhd) and DICOM series (a directory holding one series, via GDCM; a single
// DICOM file, a multi-frame volume, when it has the standard "DICM" preamble). Any pixel
// type is read as float; an image that is not 3D (a single slice counts as 2D)
// or has no voxels is refused.
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "dynsub/Volume.h"

namespace dynsub {

// The voxel spacings (mm) readVolume accepts.
constexpr double kSmallestSpacing = 1e-4, kLargestSpacing = 1e4;

// Throws dynsub::Error naming the path when it is missing, unreadable,
// truncated, of an unknown format, not 3D or empty, too large for memory, has
// a singular direction, an origin or spacing that is not finite, a spacing
// outside [kSmallestSpacing, kLargestSpacing] mm, or a voxel that is NaN or
// infinite.
Volume readVolume(const std::string& path);

// readVolume for a label map. Also throws naming the path when a voxel is not
// a whole number (a label map resampled with interpolation, or an image given
// in its place), whose value would otherwise be rounded into a neighbouring
// label without a word.
Volume readLabelMap(const std::string& path);

// Writes a mask as an unsigned 8-bit labelmap (`label` = structure, 0 =
// background; 3D Slicer colours a segment by its label value) on its grid, in
// a single-file format chosen by extension (.nii.gz for ITK-SNAP and 3D
// Slicer, .nii, .nrrd, .mha; .mhd, .nhdr and .hdr, with their separate data
// file, are refused).
// The file appears complete or not at all.
void writeMask(const Mask& mask, const std::string& path, std::uint8_t label = 1);

// How writeVolume stores voxels: as 32-bit floats (an image), or rounded to
// 16-bit signed integers (a label map).
enum class VoxelType { Float32, Label16 };

// Writes a volume on its grid, by ITK, in a single-file format chosen by
// extension (.nii.gz, .nii, .nrrd, .mha). Label values must lie in
// -32768..32767. The file appears complete or not at all.
void writeVolume(const Volume& volume, const std::string& path, VoxelType type);

// One structure of a 3D Slicer segmentation.
struct SlicerSegment {
  int label = 1;                // its value in the labelmap, 1-255
  std::string name;             // the name Slicer's Segments table shows
  std::array<double, 3> color{};  // red, green and blue, each 0-1
};

// Whether `path` names a 3D Slicer segmentation file: it ends in .seg.nrrd
// (in any case).
bool isSlicerSegmentationName(const std::string& path);

// Writes a labelmap of structures that do not overlap (0 the background,
// each segment's label on its voxels) as a 3D Slicer segmentation: a
// .seg.nrrd file, which Slicer opens as a segmentation node with the
// segments' names and colours (3D Slicer's "Segmentation labelmap file
// format": one layer of 8-bit labels on the volume's whole grid, the
// Segmentation_ and SegmentN_ fields). Throws dynsub::Error naming the path for a name not ending in
// .seg.nrrd, no segment, a label outside 1-255 or repeated, a name that is
// empty or holds a control character, a colour outside 0-1, or a voxel whose
// value is no segment's label. The file appears complete or not at all.
void writeSlicerSegmentation(const Volume& labels, const std::vector<SlicerSegment>& segments,
                             const std::string& path);
// One structure: its mask's voxels as `segment`; throws as above.
void writeSlicerSegmentation(const Mask& mask, const SlicerSegment& segment, const std::string& path);

}  // namespace dynsub
