// What the checks of every format share: inflating gzip data, the
// memory an image needs, and the choice of checks by file name (FileChecks.h).
#include "FileChecks.h"

#include <libdeflate.h>

#include <algorithm>
#include <fstream>
#include <iterator>
#include <memory>
#include <new>
#include <vector>

#include "dynsub/Error.h"
#include "dynsub/FileNames.h"
#include "dynsub/Memory.h"

namespace dynsub::filechecks {

std::vector<unsigned char> inflateGzipFile(const std::string& path, std::uintmax_t expected, std::uintmax_t start) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error(path, "cannot be opened");
  in.seekg(static_cast<std::streamoff>(start));
  const std::vector<unsigned char> packed{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  if (in.bad()) throw Error(path, "cannot be read");
  auto corrupt = [&](const std::string& why) {
    return Error(path, "truncated or corrupt compressed data (" + why + ")");
  };
  if (packed.empty()) throw corrupt("an empty file");
  // A gzip member ends with its inflated size modulo 2^32: the usual file,
  // one member under 4 GiB, is inflated in one call into a buffer of that size.
  std::size_t capacity = static_cast<std::size_t>(expected);
  if (packed.size() >= 18) {
    std::uint32_t trailer = 0;
    for (int b = 3; b >= 0; --b) trailer = trailer << 8 | packed[packed.size() - 4 + b];
    capacity = std::max<std::size_t>(capacity, trailer);
  }
  // Deflate inflates at most 1032-fold: no buffer beyond what the file can
  // hold is allocated, whatever a hostile header or trailer announces.
  const std::size_t possible = packed.size() * kLargestDeflateRatio + (1 << 16);
  const std::size_t largest =
      std::min(possible, static_cast<std::size_t>(std::min<std::uintmax_t>(expected, possible)) * 4 + (1 << 16));
  capacity = std::min(std::max<std::size_t>(capacity, 1), largest);
  const std::unique_ptr<libdeflate_decompressor, void (*)(libdeflate_decompressor*)> decompressor(
      libdeflate_alloc_decompressor(), &libdeflate_free_decompressor);
  if (!decompressor) throw std::bad_alloc();
  std::vector<unsigned char> inflated(capacity);
  std::size_t read = 0, written = 0;
  while (read < packed.size()) {  // one member after another, as gzip does
    std::size_t memberIn = 0, memberOut = 0;
    const auto result = libdeflate_gzip_decompress_ex(decompressor.get(), packed.data() + read, packed.size() - read,
                                                      inflated.data() + written, inflated.size() - written,
                                                      &memberIn, &memberOut);
    if (result == LIBDEFLATE_INSUFFICIENT_SPACE) {
      // More data than the trailer said (several members, or over 4 GiB):
      // the member is inflated again into a buffer twice as large.
      if (inflated.size() >= largest)
        throw Error(path, "inflates to more than " + std::to_string(largest) + " bytes, far beyond the " +
                              std::to_string(expected) + " its header announces");
      inflated.resize(std::min(inflated.size() * 2, largest));
      continue;
    }
    if (result != LIBDEFLATE_SUCCESS) throw corrupt("not a complete gzip stream");
    read += memberIn;
    written += memberOut;
  }
  inflated.resize(written);
  return inflated;
}

void requireMemoryFor(const std::string& path, std::uintmax_t voxels) {
  const MemoryLimit memory = usableMemory();
  if (memory.bytes == 0) return;  // unknown: left to the allocator
  const auto needed = checkedProduct(voxels, sizeof(float));
  if (!needed || *needed > memory.bytes) {
    throw Error(path, "the header announces " + std::to_string(voxels) + " voxels, " +
                          (needed ? gibibytes(*needed) : std::string("over 2^64 bytes")) + " as float, more than " +
                          memory.what + " (" + gibibytes(memory.bytes) + ")");
  }
}

DataCheck checkImageHeader(const std::string& path) {
  const std::string extension = lowerCaseExtension(path);
  if (isNiftiName(path)) return checkNiftiHeader(path);
  if (extension == ".mha" || extension == ".mhd") checkMetaImageFile(path);
  if (extension == ".nrrd") checkNrrdFile(path);
  return [] {};
}

}  // namespace dynsub::filechecks
