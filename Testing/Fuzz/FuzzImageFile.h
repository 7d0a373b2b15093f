#pragma once
// Shared by the NIfTI and MetaImage targets. The fuzzers run the project's
// own check of the file (FileChecks.h), which comes before ITK parses it;
// Debian's ITK headers compile with GCC only, so ITK is not in the clang
// fuzz build. The replay build (GCC, DYNSUB_FUZZ_WITH_ITK) also reads every
// file the check passes with readVolume, as dynsub does: a volume it returns
// must be whole and its geometry finite.
#include <cstdio>
#include <cstdlib>

#include "FileChecks.h"
#include "FuzzInput.h"
#include "dynsub/Error.h"
#ifdef DYNSUB_FUZZ_WITH_ITK
#include "dynsub/ImageIO.h"
#endif

namespace dynsub::fuzz {

template <class Check>
void checkImageFile(const std::uint8_t* data, std::size_t size, const std::string& extension, Check check) {
  const InputFile input(data, size, extension);
  try {
    check(input.path());
#ifdef DYNSUB_FUZZ_WITH_ITK
    const Volume volume = readVolume(input.path());
    const ImageGeometry& g = volume.geometry;
    requireFinite(g.spacing);
    requireFinite(g.origin);
    requireFinite(g.direction);
    if (volume.voxels.size() != static_cast<std::size_t>(g.voxelCount())) {
      std::fputs("the voxels do not fill the image's size\n", stderr);
      std::abort();
    }
#endif
  } catch (const Error& e) {
    refused(e);
  }
}

}  // namespace dynsub::fuzz
