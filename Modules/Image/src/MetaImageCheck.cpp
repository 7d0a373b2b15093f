// MetaImage files: the checks made before ITK reads them (FileChecks.h).
#include "FileChecks.h"

#include <libdeflate.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <map>
#include <memory>
#include <new>
#include <sstream>
#include <utility>
#include <vector>

#include "dynsub/Error.h"

namespace dynsub::filechecks {
namespace fs = std::filesystem;

namespace {

std::string trim(const std::string& text) {
  const auto first = text.find_first_not_of(" \t\r"), last = text.find_last_not_of(" \t\r");
  return first == std::string::npos ? std::string() : text.substr(first, last - first + 1);
}

// The bytes of one MetaImage element type, 0 for an unknown type.
int metaElementBytes(const std::string& type) {
  static const std::map<std::string, int> bytes = {
      {"MET_CHAR", 1},   {"MET_UCHAR", 1}, {"MET_SHORT", 2},     {"MET_USHORT", 2},   {"MET_INT", 4},
      {"MET_UINT", 4},   {"MET_LONG", 4},  {"MET_ULONG", 4},     {"MET_LONG_LONG", 8}, {"MET_ULONG_LONG", 8},
      {"MET_FLOAT", 4},  {"MET_DOUBLE", 8}};
  const auto found = bytes.find(type);
  return found == bytes.end() ? 0 : found->second;
}

}  // namespace

// ITK reads a short compressed .mha without complaint. Lists and patterns of
// slice files are left to ITK.
void checkMetaImageFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error(path, "cannot be opened");
  std::string line, dataFile, elementType;
  bool compressed = false, headerSize = false, binary = true;
  std::uintmax_t compressedSize = 0, channels = 1;
  std::vector<std::int64_t> size;
  long long dimensions = -1;
  // The placement's fields as written, checked once NDims is known (MetaIO
  // fails on a value that is not a number, then reports the file missing).
  std::vector<std::pair<std::string, std::string>> placement;
  auto whole = [&](const std::string& key, const std::string& value) {
    char* end = nullptr;
    errno = 0;
    const long long n = std::strtoll(value.c_str(), &end, 10);
    if (value.empty() || *end != '\0' || errno) throw Error(path, "MetaImage " + key + " '" + value + "' is not a whole number");
    return n;
  };
  while (dataFile.empty() && std::getline(in, line)) {
    const auto equals = line.find('=');
    if (equals == std::string::npos) continue;
    const std::string key = trim(line.substr(0, equals)), value = trim(line.substr(equals + 1));
    if (key == "NDims") dimensions = whole(key, value);
    if (key == "DimSize") {
      std::istringstream fields(value);
      std::string field;
      size.clear();
      while (fields >> field) size.push_back(whole(key, field));
    }
    if (key == "ElementType") elementType = value;
    if (key == "ElementNumberOfChannels") {
      const long long n = whole(key, value);
      if (n < 1 || n > 1024) throw Error(path, "MetaImage ElementNumberOfChannels " + value + " (1 to 1024 are read)");
      channels = static_cast<std::uintmax_t>(n);
    }
    if (key == "CompressedData") compressed = value == "True" || value == "true";
    if (key == "CompressedDataSize") {
      const long long n = whole(key, value);
      if (n < 0) throw Error(path, "MetaImage CompressedDataSize is negative");
      compressedSize = static_cast<std::uintmax_t>(n);
    }
    if (key == "HeaderSize") headerSize = true;
    if (key == "BinaryData") binary = value != "False" && value != "false";
    if (key == "ElementSpacing" || key == "Offset" || key == "Origin" || key == "Position" ||
        key == "CenterOfRotation" || key == "TransformMatrix" || key == "Rotation" || key == "Orientation")
      placement.emplace_back(key, value);
    if (key == "ElementDataFile") dataFile = value;
  }
  if (dataFile.empty()) throw Error(path, "a MetaImage header without ElementDataFile");
  if (dimensions < 1 || dimensions > 10)
    throw Error(path, "a MetaImage header with NDims " + std::to_string(dimensions) + " (1 to 10 are read)");
  for (const auto& [key, value] : placement) {
    std::istringstream fields(value);
    std::size_t count = 0;
    for (std::string field; fields >> field; ++count) {
      char* end = nullptr;
      const double number = std::strtod(field.c_str(), &end);
      if (*end != '\0' || !std::isfinite(number))
        throw Error(path, "MetaImage " + key + " holds '" + field + "', not a finite number");
    }
    const bool matrix = key == "TransformMatrix" || key == "Rotation" || key == "Orientation";
    const std::size_t expected = static_cast<std::size_t>(matrix ? dimensions * dimensions : dimensions);
    if (count != expected)
      throw Error(path, "MetaImage " + key + " has " + std::to_string(count) + " values for NDims " +
                            std::to_string(dimensions) + " (expected " + std::to_string(expected) + ")");
  }
  if (static_cast<long long>(size.size()) != dimensions)
    throw Error(path, "MetaImage DimSize has " + std::to_string(size.size()) + " sizes for NDims " +
                          std::to_string(dimensions));
  std::uintmax_t voxels = 1;
  for (std::size_t a = 0; a < size.size(); ++a) {
    if (size[a] < 1)
      throw Error(path, "MetaImage DimSize " + std::to_string(size[a]) + " along axis " + std::to_string(a));
    const auto next = checkedProduct(voxels, static_cast<std::uintmax_t>(size[a]));
    if (!next) throw Error(path, "a MetaImage header whose size does not fit in 64 bits");
    voxels = *next;
  }
  const int elementBytes = metaElementBytes(elementType);
  if (!elementBytes) throw Error(path, "MetaImage ElementType '" + elementType + "' is not one that is read");
  requireMemoryFor(path, voxels);
  const auto voxelBytes = checkedProduct(voxels, channels * static_cast<std::uintmax_t>(elementBytes));
  if (!voxelBytes) throw Error(path, "a MetaImage header whose size does not fit in 64 bits");
  std::uintmax_t available = 0;
  std::string source = path;
  std::streamoff dataStart = 0;
  if (dataFile == "LOCAL") {
    dataStart = std::max<std::streamoff>(in.tellg(), 0);
    available = fs::file_size(path) - static_cast<std::uintmax_t>(dataStart);
  } else if (dataFile.find_first_of("% ") == std::string::npos && dataFile != "LIST") {
    source = (fs::path(path).parent_path() / dataFile).string();
    std::error_code error;
    available = fs::file_size(source, error);
    if (error) throw Error(path, "its data file " + source + " cannot be read");
  } else {
    return;
  }
  // Data written as text has no size to check here.
  if (!binary) return;
  const std::uintmax_t needed = compressed ? compressedSize : *voxelBytes;
  if (available < needed)
    throw Error(source, "truncated: " + std::to_string(available) + " bytes of data, the header announces " +
                            std::to_string(needed));
  // More raw data than announced: the header's DimSize or ElementType is not
  // the data's, and ITK would read its first bytes as the image. (A
  // HeaderSize skips bytes before the data, which are then not counted here.)
  if (!compressed && !headerSize && available > needed)
    throw Error(source, std::to_string(available) + " bytes of data, where the header announces " +
                            std::to_string(needed) + ": its DimSize or ElementType does not describe the data");
  // Compressed data must inflate to exactly the voxels' bytes: on a corrupt
  // stream MetaIO prints "Uncompress failed" and ITK returns whatever image
  // it got. (Without CompressedDataSize the stream runs to the file's end.)
  if (compressed && !headerSize) {
    std::vector<unsigned char> packed(static_cast<std::size_t>(compressedSize ? compressedSize : available));
    std::ifstream data(source, std::ios::binary);
    data.seekg(dataStart);
    data.read(reinterpret_cast<char*>(packed.data()), static_cast<std::streamsize>(packed.size()));
    if (!data) throw Error(source, "its compressed data cannot be read");
    // Deflate inflates at most kLargestDeflateRatio-fold: a header that
    // announces more is refused before a buffer of its size is allocated.
    if (*voxelBytes / kLargestDeflateRatio > packed.size())
      throw Error(source, "corrupt header: " + std::to_string(packed.size()) +
                              " bytes of compressed data cannot hold the " + std::to_string(*voxelBytes) +
                              " bytes it announces");
    const std::unique_ptr<libdeflate_decompressor, void (*)(libdeflate_decompressor*)> decompressor(
        libdeflate_alloc_decompressor(), &libdeflate_free_decompressor);
    if (!decompressor) throw std::bad_alloc();
    std::vector<unsigned char> voxels(static_cast<std::size_t>(*voxelBytes));
    std::size_t inflated = 0;
    const auto result = libdeflate_zlib_decompress(decompressor.get(), packed.data(), packed.size(), voxels.data(),
                                                   voxels.size(), &inflated);
    if (result != LIBDEFLATE_SUCCESS || inflated != voxels.size())
      throw Error(source,
                  std::string("corrupt compressed data: it ") +
                      (result == LIBDEFLATE_INSUFFICIENT_SPACE ? "inflates to more than"
                       : result == LIBDEFLATE_SUCCESS ? "inflates to " + std::to_string(inflated) + " bytes, not"
                                                      : "is not a complete zlib stream of") +
                      " the " + std::to_string(*voxelBytes) + " bytes the header announces");
  }
}

}  // namespace dynsub::filechecks
