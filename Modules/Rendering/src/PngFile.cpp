#include "PngFile.h"

#include <libdeflate.h>

#include <array>
#include <cmath>
#include <cstdint>
#include <fstream>
#include <memory>
#include <vector>

#include "dynsub/AtomicOutput.h"
#include "dynsub/Error.h"

namespace dynsub {
namespace {

void putBigEndian(std::vector<unsigned char>& bytes, std::uint32_t value) {
  for (int shift = 24; shift >= 0; shift -= 8) bytes.push_back(static_cast<unsigned char>(value >> shift));
}

// One chunk: its length, type, data and the CRC-32 of type and data.
void putChunk(std::vector<unsigned char>& file, const char (&type)[5], const unsigned char* data, std::size_t size) {
  putBigEndian(file, static_cast<std::uint32_t>(size));
  const std::size_t typeAt = file.size();
  file.insert(file.end(), type, type + 4);
  file.insert(file.end(), data, data + size);
  putBigEndian(file, libdeflate_crc32(0, file.data() + typeAt, 4 + size));
}

}  // namespace

void writePngFile(const std::string& path, int width, int height, int channels, const unsigned char* bottomRowFirst,
                  double dpi) {
  if (width < 1 || height < 1 || (channels != 3 && channels != 4) || !bottomRowFirst || !(dpi > 0))
    throw Error(path, "internal: a PNG of " + std::to_string(width) + " x " + std::to_string(height) + " pixels of " +
                          std::to_string(channels) + " channels");
  // The rows top first, each behind its filter byte: 2, "up", each sample
  // less the one above it (modulo 256; nothing above the top row).
  const std::size_t rowBytes = static_cast<std::size_t>(width) * channels;
  std::vector<unsigned char> filtered((rowBytes + 1) * height);
  for (int y = 0; y < height; ++y) {
    const unsigned char* row = bottomRowFirst + rowBytes * (height - 1 - y);
    const unsigned char* above = y > 0 ? row + rowBytes : nullptr;
    unsigned char* out = &filtered[(rowBytes + 1) * y];
    out[0] = 2;
    for (std::size_t i = 0; i < rowBytes; ++i) out[1 + i] = static_cast<unsigned char>(row[i] - (above ? above[i] : 0));
  }
  // Level 4: as small as VTK's files at its default level, at about a
  // third of the time of level 6.
  const std::unique_ptr<libdeflate_compressor, void (*)(libdeflate_compressor*)> compressor(
      libdeflate_alloc_compressor(4), libdeflate_free_compressor);
  if (!compressor) throw writeFailure(path, "no memory to compress the image");
  std::vector<unsigned char> deflated(libdeflate_zlib_compress_bound(compressor.get(), filtered.size()));
  const std::size_t deflatedSize =
      libdeflate_zlib_compress(compressor.get(), filtered.data(), filtered.size(), deflated.data(), deflated.size());
  if (deflatedSize == 0) throw writeFailure(path, "the image could not be compressed");

  std::vector<unsigned char> file = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
  std::vector<unsigned char> header;
  putBigEndian(header, static_cast<std::uint32_t>(width));
  putBigEndian(header, static_cast<std::uint32_t>(height));
  // 8 bits per sample, RGB (2) or RGBA (6), deflate, adaptive filtering, no interlace.
  header.insert(header.end(), {8, static_cast<unsigned char>(channels == 3 ? 2 : 6), 0, 0, 0});
  putChunk(file, "IHDR", header.data(), header.size());
  // Pixels per metre, the same across and down, unit 1 (the metre).
  std::vector<unsigned char> physical;
  const auto perMetre = static_cast<std::uint32_t>(std::lround(dpi / 0.0254));
  putBigEndian(physical, perMetre);
  putBigEndian(physical, perMetre);
  physical.push_back(1);
  putChunk(file, "pHYs", physical.data(), physical.size());
  putChunk(file, "IDAT", deflated.data(), deflatedSize);
  putChunk(file, "IEND", nullptr, 0);
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(file.data()), static_cast<std::streamsize>(file.size()));
  out.close();
  if (!out) throw writeFailure(path);
}

}  // namespace dynsub
