// NRRD files: the check made before ITK reads them (FileChecks.h).
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>

#include "FileChecks.h"
#include "dynsub/Error.h"

namespace dynsub::filechecks {
namespace fs = std::filesystem;

namespace {

// The bytes of one NRRD type, by each of the names the format gives it; 0
// for another.
int nrrdTypeBytes(const std::string& type) {
  static const std::map<std::string, int> bytes = {
      {"signed char", 1}, {"int8", 1}, {"int8_t", 1}, {"uchar", 1}, {"unsigned char", 1}, {"uint8", 1},
      {"uint8_t", 1}, {"short", 2}, {"short int", 2}, {"signed short", 2}, {"signed short int", 2},
      {"int16", 2}, {"int16_t", 2}, {"ushort", 2}, {"unsigned short", 2}, {"unsigned short int", 2},
      {"uint16", 2}, {"uint16_t", 2}, {"int", 4}, {"signed int", 4}, {"int32", 4}, {"int32_t", 4},
      {"uint", 4}, {"unsigned int", 4}, {"uint32", 4}, {"uint32_t", 4}, {"float", 4},
      {"longlong", 8}, {"long long", 8}, {"long long int", 8}, {"signed long long", 8},
      {"signed long long int", 8}, {"int64", 8}, {"int64_t", 8}, {"ulonglong", 8},
      {"unsigned long long", 8}, {"unsigned long long int", 8}, {"uint64", 8}, {"uint64_t", 8},
      {"double", 8}};
  const auto found = bytes.find(type);
  return found == bytes.end() ? 0 : found->second;
}

}  // namespace

void checkNrrdFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return;  // ITK's reader says why
  std::string line, type, encoding;
  std::uintmax_t voxels = 0;
  bool detachedOrSkipped = false;
  // The header ends at its first empty line; the data follows.
  while (std::getline(in, line)) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.empty()) break;
    if (line[0] == '#') continue;
    const auto colon = line.find(": ");
    if (colon == std::string::npos) continue;
    const std::string key = line.substr(0, colon), value = line.substr(colon + 2);
    if (key == "type") type = value;
    if (key == "encoding") encoding = value;
    if (key == "sizes") {
      std::istringstream sizes(value);
      voxels = 1;
      for (std::uintmax_t size = 0; sizes >> size;)
        if (__builtin_mul_overflow(voxels, size, &voxels)) return;  // the memory check refuses it
    }
    if (key == "data file" || key == "datafile" || key == "line skip" || key == "lineskip" || key == "byte skip" ||
        key == "byteskip")
      detachedOrSkipped = true;
  }
  const int bytes = nrrdTypeBytes(type);
  const bool gzip = encoding == "gzip" || encoding == "gz";
  if (!in || !(encoding == "raw" || gzip) || detachedOrSkipped || bytes == 0 || voxels == 0) return;
  const auto at = static_cast<std::uintmax_t>(in.tellg());
  std::uintmax_t needed = 0;
  if (__builtin_mul_overflow(voxels, static_cast<std::uintmax_t>(bytes), &needed)) return;
  // Gzip data (3D Slicer's default) is inflated to be measured.
  const std::uintmax_t available = gzip ? inflateGzipFile(path, needed, at).size() : fs::file_size(path) - at;
  // Less is ITK's to report (it reads that far); more would be read as the
  // image's first bytes, the rest dropped.
  if (available > needed)
    throw Error(path, std::to_string(available) + " bytes of data, where the header announces " +
                          std::to_string(needed) + ": its sizes or type do not describe the data");
}

}  // namespace dynsub::filechecks
