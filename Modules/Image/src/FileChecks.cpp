// What the checks of every format share: the inflated size of gzip data, the
// memory an image needs, and the choice of checks by file name (FileChecks.h).
#include "FileChecks.h"

#include <unistd.h>
#include <zlib.h>

#include <vector>

#include "dynsub/Error.h"
#include "dynsub/FileNames.h"

namespace dynsub::filechecks {

std::uintmax_t inflatedSize(const std::string& path, std::uintmax_t enough) {
  gzFile file = gzopen(path.c_str(), "rb");
  if (!file) throw Error(path, "cannot be opened");
  std::vector<char> buffer(1 << 16);
  std::uintmax_t total = 0;
  int read = 0;
  while (total < enough && (read = gzread(file, buffer.data(), static_cast<unsigned>(buffer.size()))) > 0)
    total += read;
  int code = Z_OK;
  std::string message = gzerror(file, &code);
  gzclose(file);
  // zlib's message starts with the path, which the error names already.
  if (message.rfind(path + ": ", 0) == 0) message.erase(0, path.size() + 2);
  if (read < 0 || (code != Z_OK && code != Z_STREAM_END))
    throw Error(path, "truncated or corrupt compressed data (" + message + ") after " + std::to_string(total) +
                          " bytes");
  return total;
}

void requireMemoryFor(const std::string& path, std::uintmax_t voxels) {
  const long pages = sysconf(_SC_PHYS_PAGES), pageSize = sysconf(_SC_PAGE_SIZE);
  if (pages <= 0 || pageSize <= 0) return;  // unknown: left to the allocator
  const auto memory = static_cast<std::uintmax_t>(pages) * static_cast<std::uintmax_t>(pageSize);
  const auto needed = checkedProduct(voxels, sizeof(float));
  if (!needed || *needed > memory) {
    auto gib = [](long double bytes) { return std::to_string(static_cast<long long>(bytes / (1 << 30))); };
    throw Error(path, "the header announces " + std::to_string(voxels) + " voxels, " +
                          (needed ? gib(*needed) : std::string("over 2^64 bytes")) + " GiB as float, more than " +
                          "this machine's " + gib(memory) + " GiB of memory");
  }
}

void checkImageFile(const std::string& path) {
  const std::string extension = lowerCaseExtension(path);
  if (isNiftiName(path)) checkNiftiFile(path);
  if (extension == ".mha" || extension == ".mhd") checkMetaImageFile(path);
}

}  // namespace dynsub::filechecks
