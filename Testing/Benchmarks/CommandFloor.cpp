// What a segmentation command pays besides segmenting, each part timed alone
// in one process (ITK's filter alone, which the whole `dynsub segment` is
// compared with, pays none of them):
//   build/bin/CommandFloor IMAGE.nii.gz LABELMAP.nii.gz
// prints, in ms: opening CHOLMOD's chain of libraries (as every simulating
// command links it), opening DynSub's ITK bridge (ITK's IO and filters, as
// `segment` does to read the image's geometry and smooth it), reading and
// inflating IMAGE (each timed), and deflating LABELMAP's voxels at the labelmap writer's
// level. The process's own start (libstdc++, libdeflate) is measured from
// outside: `perf stat -r 30 build/bin/CommandFloor --start`.
#include <dlfcn.h>
#include <libdeflate.h>

#include <chrono>
#include <cstdio>
#include <fstream>
#include <memory>
#include <string>

namespace {

double msSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}

std::string fileBytes(const char* path) {
  std::ifstream in(path, std::ios::binary | std::ios::ate);
  std::string bytes(in ? static_cast<std::size_t>(in.tellg()) : 0, '\0');
  in.seekg(0);
  in.read(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  return bytes;
}

// Bytes left uninitialized, as the readers and writers keep them: a page is
// touched only when written.
struct Bytes {
  std::unique_ptr<char[]> data;
  std::size_t size = 0;
};

// The gzip member inflated (its size is its last four bytes, modulo 2^32);
// empty when it is not one.
Bytes inflated(const std::string& packed) {
  if (packed.size() < 18) return {};
  const auto* tail = reinterpret_cast<const unsigned char*>(packed.data() + packed.size() - 4);
  Bytes out{nullptr, tail[0] | tail[1] << 8 | tail[2] << 16 | static_cast<std::size_t>(tail[3]) << 24};
  out.data.reset(new char[out.size]);
  libdeflate_decompressor* d = libdeflate_alloc_decompressor();
  const bool ok = libdeflate_gzip_decompress(d, packed.data(), packed.size(), out.data.get(), out.size, nullptr) ==
                  LIBDEFLATE_SUCCESS;
  libdeflate_free_decompressor(d);
  if (!ok) out.size = 0;
  return out;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc == 2 && std::string(argv[1]) == "--start") return 0;
  if (argc != 3) {
    std::fprintf(stderr, "usage: CommandFloor IMAGE.nii.gz LABELMAP.nii.gz | --start\n");
    return 2;
  }
  auto start = std::chrono::steady_clock::now();
  if (!dlopen("libcholmod.so.3", RTLD_NOW | RTLD_LOCAL)) {
    std::fprintf(stderr, "CommandFloor: %s\n", dlerror());
    return 1;
  }
  const double cholmod = msSince(start);
  start = std::chrono::steady_clock::now();
  if (!dlopen(DYNSUB_ITK_BRIDGE_BUILD_PATH, RTLD_NOW | RTLD_LOCAL)) {
    std::fprintf(stderr, "CommandFloor: %s\n", dlerror());
    return 1;
  }
  const double bridge = msSince(start);
  start = std::chrono::steady_clock::now();
  const std::string file = fileBytes(argv[1]);
  const double read = msSince(start);
  start = std::chrono::steady_clock::now();
  const Bytes image = inflated(file);
  const double inflate = msSince(start);
  const Bytes labelmap = inflated(fileBytes(argv[2]));
  if (image.size == 0 || labelmap.size == 0) {
    std::fprintf(stderr, "CommandFloor: %s or %s is not a readable gzip file\n", argv[1], argv[2]);
    return 1;
  }
  start = std::chrono::steady_clock::now();
  libdeflate_compressor* c = libdeflate_alloc_compressor(6);  // NiftiLabelmap.cpp's kCompressionLevel
  Bytes packed{nullptr, libdeflate_gzip_compress_bound(c, labelmap.size)};
  packed.data.reset(new char[packed.size]);
  const std::size_t size = libdeflate_gzip_compress(c, labelmap.data.get(), labelmap.size, packed.data.get(), packed.size);
  libdeflate_free_compressor(c);
  const double deflate = msSince(start);
  std::printf("cholmod %.1f ms, itk bridge %.1f ms, read %.1f ms (%zu bytes), inflate %.1f ms (%zu bytes), "
              "deflate %.1f ms (%zu bytes)\n",
              cholmod, bridge, read, file.size(), inflate, image.size, deflate, size);
  return size > 0 ? 0 : 1;
}
