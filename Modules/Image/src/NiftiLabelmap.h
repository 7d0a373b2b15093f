#pragma once
// Private to the Image module: labelmaps written as NIfTI-1 by DynSub itself.
// ITK 5.2's writer copies the image twice and then compresses it with zlib's
// default level, which it does not let a caller change; a labelmap, long
// runs of one value, compresses about three times faster with zlib's
// run-length strategy (Documentation/Performance.md). The header says what ITK's writer says:
// the same fields, codes and geometry (NiftiLabelmapUnitTests hold the two to
// each other through ITK's reader).
#include <cstdint>
#include <string>

#include "dynsub/Volume.h"

namespace dynsub {

// The NIfTI-1 file, one piece (.nii), or that compressed as one gzip member
// (.nii.gz, by zlib), of `mask` on its geometry with `label` where the
// mask is set and 0 elsewhere, as unsigned 8-bit values; `path` is a NIfTI
// name (FileChecks.h: isNiftiName). Throws dynsub::Error naming `path` when
// the grid does not fit NIfTI-1 (more than 32 767 voxels along an axis) or
// the file cannot be written.
void writeNiftiLabelmap(const Mask& mask, std::uint8_t label, const std::string& path);

}  // namespace dynsub
