#include "FileChecks.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <sstream>
#include <vector>

#include <unistd.h>
#include <libdeflate.h>
#include <zlib.h>

#include "dynsub/Error.h"
#include "dynsub/FileNames.h"

namespace dynsub::filechecks {
namespace fs = std::filesystem;

namespace {
// GDCM, as Debian builds it, aborts the process (a failed assertion) on a
// file cut short before its pixel data. So the elements of each DICOM file are
// walked first, and each must fit in the file: the meta header (explicit VR,
// little endian), then a data set in either uncompressed little-endian
// transfer syntax (explicit or implicit VR), sequences and items of undefined
// length included, and encapsulated pixel data fragment by fragment. A data
// set in another transfer syntax (deflated, big endian) is left to GDCM:
// run() says whether the whole file was walked.
class DicomWalk {
 public:
  explicit DicomWalk(const fs::path& file) : file_(file), size_(fs::file_size(file)), in_(file, std::ios::binary) {}

  bool run() {
    std::uintmax_t at = 132;
    // The meta header: explicit VR little endian, group 0002, first; its
    // length, when given (0002,0000), must be there too.
    if (group(at) == 0x0002 && number(at + 2, 2) == 0x0000 && 144 + number(at + 8, 4) > size_)
      fail("the meta header needs " + std::to_string(number(at + 8, 4)) + " bytes, the file has " +
           std::to_string(size_ - std::min<std::uintmax_t>(size_, 144)));
    while (at < size_ && group(at) == 0x0002) at = element(at);
    if (syntax_.empty()) fail("the meta header ends before its transfer syntax");
    if (at >= size_) fail("nothing follows the meta header");
    if (syntax_ == "1.2.840.10008.1.2") {
      explicitVr_ = false;
    } else if (syntax_ != "1.2.840.10008.1.2.1" && !isEncapsulated()) {
      return false;  // deflated or big endian: GDCM's alone
    }
    elements(at, false);
    return true;
  }

 private:
  static constexpr std::uint32_t kUndefined = 0xFFFFFFFFu;

  [[noreturn]] void fail(const std::string& what) const {
    throw Error(file_.string(), "a truncated DICOM file: " + what);
  }
  // Little-endian unsigned of n bytes at `at`; fails beyond the end.
  std::uint32_t number(std::uintmax_t at, int n) {
    if (at + n > size_) fail("an element is cut short at byte " + std::to_string(at));
    unsigned char bytes[4] = {};
    in_.seekg(static_cast<std::streamoff>(at));
    in_.read(reinterpret_cast<char*>(bytes), n);
    std::uint32_t v = 0;
    for (int i = n - 1; i >= 0; --i) v = (v << 8) | bytes[i];
    return v;
  }
  unsigned group(std::uintmax_t at) { return number(at, 2); }
  // JPEG, JPEG-LS, JPEG 2000, RLE: explicit VR little endian with encapsulated pixel data.
  bool isEncapsulated() const {
    return syntax_.rfind("1.2.840.10008.1.2.4.", 0) == 0 || syntax_ == "1.2.840.10008.1.2.5";
  }

  // Elements from `at` to the end of the file or, in an item of undefined
  // length, to its delimiter; returns the position after them.
  std::uintmax_t elements(std::uintmax_t at, bool inItem) {
    while (at < size_) {
      if (group(at) == 0xFFFE) {
        if (inItem && number(at + 2, 2) == 0xE00D) return at + 8;
        fail("a stray item delimiter at byte " + std::to_string(at));
      }
      at = element(at);
    }
    if (inItem) fail("an item of undefined length has no end");
    return at;
  }

  // One element at `at`; returns the position after it.
  std::uintmax_t element(std::uintmax_t at) {
    const unsigned tagGroup = group(at), tagElement = number(at + 2, 2);
    std::uintmax_t header = 8;
    std::uint32_t length = 0;
    const bool explicitVr = explicitVr_ || tagGroup == 0x0002;
    if (explicitVr) {
      const std::uint32_t vr = number(at + 4, 2);
      const std::string name{static_cast<char>(vr & 0xFF), static_cast<char>(vr >> 8)};
      static const std::set<std::string> longLength = {"OB", "OD", "OF", "OL", "OV", "OW", "SQ",
                                                       "SV", "UC", "UN", "UR", "UT", "UV"};
      if (longLength.count(name)) {
        length = number(at + 8, 4);
        header = 12;
      } else {
        length = number(at + 6, 2);
      }
    } else {
      length = number(at + 4, 4);
    }
    if (length == kUndefined) return sequence(at + header);  // a sequence, or encapsulated pixel data
    if (at + header + length > size_) {
      char name[16];
      std::snprintf(name, sizeof name, "(%04x,%04x)", tagGroup, tagElement);
      fail(std::string("element ") + name + " needs " + std::to_string(length) + " bytes, the file has " +
           std::to_string(size_ - at - header));
    }
    if (tagGroup == 0x0002 && tagElement == 0x0010) {  // the transfer syntax UID
      std::string value(length, '\0');
      in_.seekg(static_cast<std::streamoff>(at + header));
      in_.read(value.data(), static_cast<std::streamsize>(length));
      while (!value.empty() && (value.back() == '\0' || value.back() == ' ')) value.pop_back();
      syntax_ = value;
    }
    return at + header + length;
  }

  // Items (or pixel data fragments) up to the sequence delimiter.
  std::uintmax_t sequence(std::uintmax_t at) {
    while (true) {
      if (group(at) != 0xFFFE) fail("a sequence without its delimiter at byte " + std::to_string(at));
      const unsigned tagElement = number(at + 2, 2);
      const std::uint32_t length = number(at + 4, 4);
      if (tagElement == 0xE0DD) return at + 8;
      if (tagElement != 0xE000) fail("a sequence holds something other than items at byte " + std::to_string(at));
      if (length == kUndefined) {
        at = elements(at + 8, true);
      } else {
        if (at + 8 + length > size_)
          fail("an item needs " + std::to_string(length) + " bytes, the file has " + std::to_string(size_ - at - 8));
        at += 8 + length;
      }
    }
  }

  fs::path file_;
  std::uintmax_t size_;
  std::ifstream in_;
  bool explicitVr_ = true;
  std::string syntax_;
};



// a * b, or nothing when the product does not fit.
std::optional<std::uintmax_t> product(std::uintmax_t a, std::uintmax_t b) {
  std::uintmax_t result = 0;
  if (__builtin_mul_overflow(a, b, &result)) return std::nullopt;
  return result;
}

std::string trim(const std::string& text) {
  const auto first = text.find_first_not_of(" \t\r"), last = text.find_last_not_of(" \t\r");
  return first == std::string::npos ? std::string() : text.substr(first, last - first + 1);
}

// The bytes per voxel of a NIfTI datatype code, 0 for a code NIfTI does not define.
int niftiBytesPerVoxel(int datatype) {
  switch (datatype) {
    case 2: case 256: return 1;             // uint8, int8
    case 4: case 512: return 2;             // int16, uint16
    case 128: return 3;                     // RGB24
    case 8: case 16: case 768: case 2304: return 4;  // int32, float32, uint32, RGBA32
    case 32: case 64: case 1024: case 1280: return 8;  // complex64, float64, int64, uint64
    case 1536: case 1792: return 16;        // float128, complex128
    case 2048: return 32;                   // complex256
    default: return 0;
  }
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


// The error for `bad` NaN or infinite voxels, the first at index `first`.
std::string nonFiniteMessage(std::uintmax_t bad, std::uintmax_t first, const std::array<std::int64_t, 3>& size) {
  const std::uintmax_t i = first % size[0], j = first / size[0] % size[1], k = first / size[0] / size[1];
  return std::to_string(bad) + " voxel(s) are NaN or infinite, the first at index (" + std::to_string(i) + ", " +
         std::to_string(j) + ", " + std::to_string(k) + "); intensities must be finite";
}

// What zlib says of a gzip stream read so far: whether it failed (corrupt or
// cut short), and its message without the path zlib puts first.
struct ZlibState {
  bool failed;
  std::string message;
};

ZlibState zlibState(const std::string& path, gzFile file) {
  int code = Z_OK;
  std::string message = gzerror(file, &code);
  if (message.rfind(path + ": ", 0) == 0) message.erase(0, path.size() + 2);
  return {code != Z_OK && code != Z_STREAM_END, message};
}

Error corruptCompressedData(const std::string& path, const std::string& zlibMessage, std::uintmax_t inflated) {
  return Error(path, "truncated or corrupt compressed data (" + zlibMessage + ") after " + std::to_string(inflated) +
                         " bytes");
}

// A NIfTI file whose data ends (`actual` bytes, inflated when gzipped) before
// the `needed` bytes its header announces.
Error truncatedData(const std::string& path, std::uintmax_t actual, bool gzipped, std::uintmax_t needed) {
  return Error(path, "truncated: " + std::to_string(actual) + (gzipped ? " bytes inflated" : " bytes") +
                         ", the header announces " + std::to_string(needed));
}

// Scans `voxels` float (4-byte) or double (8-byte) values from byte `offset`
// of a file (inflated when gzipped); throws naming the count of NaN or
// infinite ones and the voxel index (i, j, k) of the first.
void requireFiniteVoxels(const std::string& path, bool gzipped, std::uintmax_t offset, std::uintmax_t voxels,
                         int bytes, bool swap, const std::array<std::int64_t, 3>& size) {
  gzFile file = gzopen(path.c_str(), "rb");  // reads plain files too
  if (!file) throw Error(path, "cannot be opened");
  std::vector<unsigned char> buffer(static_cast<std::size_t>(bytes) << 14);
  std::uintmax_t done = 0, bad = 0, first = 0;
  bool ok = gzseek(file, static_cast<z_off_t>(offset), SEEK_SET) >= 0;
  while (ok && done < voxels) {
    const auto want = static_cast<unsigned>(std::min<std::uintmax_t>(voxels - done, buffer.size() / bytes) * bytes);
    ok = gzread(file, buffer.data(), want) == static_cast<int>(want);
    for (unsigned at = 0; ok && at < want; at += bytes) {
      unsigned char* value = &buffer[at];
      if (swap) std::reverse(value, value + bytes);
      double number = 0;
      if (bytes == 4) {
        float f = 0;
        std::memcpy(&f, value, 4);
        number = f;
      } else {
        std::memcpy(&number, value, 8);
      }
      if (!std::isfinite(number) && bad++ == 0) first = done + at / bytes;
    }
    done += want / bytes;
  }
  gzclose(file);
  if (!ok) throw Error(path, std::string("cannot read its ") + (gzipped ? "compressed " : "") + "voxels");
  if (bad) throw Error(path, nonFiniteMessage(bad, first, size));
}

}  // namespace

std::uintmax_t inflatedSize(const std::string& path, std::uintmax_t enough) {
  gzFile file = gzopen(path.c_str(), "rb");
  if (!file) throw Error(path, "cannot be opened");
  std::vector<char> buffer(1 << 16);
  std::uintmax_t total = 0;
  int read = 0;
  while (total < enough && (read = gzread(file, buffer.data(), static_cast<unsigned>(buffer.size()))) > 0)
    total += read;
  const ZlibState state = zlibState(path, file);
  gzclose(file);
  if (read < 0 || state.failed) throw corruptCompressedData(path, state.message, total);
  return total;
}

void requireMemoryFor(const std::string& path, std::uintmax_t voxels) {
  const long pages = sysconf(_SC_PHYS_PAGES), pageSize = sysconf(_SC_PAGE_SIZE);
  if (pages <= 0 || pageSize <= 0) return;  // unknown: left to the allocator
  const auto memory = static_cast<std::uintmax_t>(pages) * static_cast<std::uintmax_t>(pageSize);
  const auto needed = product(voxels, sizeof(float));
  if (!needed || *needed > memory) {
    auto gib = [](long double bytes) { return std::to_string(static_cast<long long>(bytes / (1 << 30))); };
    throw Error(path, "the header announces " + std::to_string(voxels) + " voxels, " +
                          (needed ? gib(*needed) : std::string("over 2^64 bytes")) + " GiB as float, more than " +
                          "this machine's " + gib(memory) + " GiB of memory");
  }
}

namespace {

// `n` stored values of type T (in the file's byte order) as float, the way
// ITK's reader turns them into float: static_cast.
template <class T>
void storedAsFloat(const unsigned char* bytes, std::size_t n, bool swap, float* out) {
  for (std::size_t v = 0; v < n; ++v, bytes += sizeof(T)) {
    unsigned char value[sizeof(T)];
    std::memcpy(value, bytes, sizeof(T));
    if (swap) std::reverse(value, value + sizeof(T));
    T number;
    std::memcpy(&number, value, sizeof(T));
    out[v] = static_cast<float>(number);
  }
}

using StoredAsFloat = void (*)(const unsigned char*, std::size_t, bool, float*);

// The conversion of a NIfTI datatype DynSub reads itself (readNiftiVoxels),
// or null.
StoredAsFloat converterOf(int datatype) {
  switch (datatype) {
    case 2: return &storedAsFloat<std::uint8_t>;
    case 256: return &storedAsFloat<std::int8_t>;
    case 4: return &storedAsFloat<std::int16_t>;
    case 512: return &storedAsFloat<std::uint16_t>;
    case 8: return &storedAsFloat<std::int32_t>;
    case 768: return &storedAsFloat<std::uint32_t>;
    case 16: return &storedAsFloat<float>;
    case 64: return &storedAsFloat<double>;
    default: return nullptr;
  }
}

// The bytes from `offset` on of a .nii or .nii.gz, in chunks: read(into, n)
// returns how many of n bytes it got (fewer only at the end of the data).
class DataReader {
 public:
  DataReader(const std::string& path, bool gzipped, std::uintmax_t offset) : path_(path), gzipped_(gzipped) {
    if (gzipped_) {
      gz_ = gzopen(path.c_str(), "rb");
      if (!gz_) throw Error(path, "cannot be opened");
      gzbuffer(gz_, 1 << 17);
      ok_ = gzseek(gz_, static_cast<z_off_t>(offset), SEEK_SET) >= 0;
    } else {
      in_.open(path, std::ios::binary);
      if (!in_) throw Error(path, "cannot be opened");
      ok_ = static_cast<bool>(in_.seekg(static_cast<std::streamoff>(offset)));
    }
  }
  ~DataReader() {
    if (gz_) gzclose(gz_);
  }
  DataReader(const DataReader&) = delete;
  DataReader& operator=(const DataReader&) = delete;

  std::size_t read(unsigned char* into, std::size_t n) {
    if (!ok_) return 0;
    if (gzipped_) {
      const int got = gzread(gz_, into, static_cast<unsigned>(n));
      if (got < 0) ok_ = false;
      return got > 0 ? static_cast<std::size_t>(got) : 0;
    }
    in_.read(reinterpret_cast<char*>(into), static_cast<std::streamsize>(n));
    return static_cast<std::size_t>(in_.gcount());
  }
  // Why the data ended early, in the words of inflatedSize's error.
  [[noreturn]] void fail(std::uintmax_t inflated, std::uintmax_t needed) {
    if (gzipped_ && gz_) {
      const ZlibState state = zlibState(path_, gz_);
      if (state.failed) throw corruptCompressedData(path_, state.message, inflated);
    }
    throw truncatedData(path_, inflated, gzipped_, needed);
  }

 private:
  std::string path_;
  bool gzipped_;
  gzFile gz_ = nullptr;
  std::ifstream in_;
  bool ok_ = false;
};

// A .nii.gz inflated whole in memory with libdeflate, about twice as fast
// as zlib's stream (13 against 28 ms for Colin27), when it is one gzip
// member of at most kWholeInflateLimit bytes that inflates to at least
// `needed`; empty otherwise, and for any error, which the stream path
// then reports in zlib's words.
constexpr std::uintmax_t kWholeInflateLimit = std::uintmax_t{1} << 29;

// Bytes left uninitialized until written: value-initializing (std::vector's
// resize) the compressed and inflated copies of an image wrote every byte
// once more before it was read or inflated into.
struct Bytes {
  std::unique_ptr<unsigned char[]> data;
  std::size_t size = 0;
  Bytes() = default;
  explicit Bytes(std::size_t n) : data(new unsigned char[n]), size(n) {}
  bool empty() const { return size == 0; }
};

Bytes inflateWhole(const std::string& path, std::uintmax_t needed) {
  std::error_code failed;
  const std::uintmax_t size = fs::file_size(path, failed);
  if (failed || size < 18 || size > kWholeInflateLimit) return {};
  std::ifstream in(path, std::ios::binary);
  Bytes compressed(static_cast<std::size_t>(size));
  if (!in.read(reinterpret_cast<char*>(compressed.data.get()), static_cast<std::streamsize>(size))) return {};
  // The trailer's ISIZE: the inflated size modulo 2^32 (a larger file fails below).
  std::uint32_t inflatedSize = 0;
  for (int b = 3; b >= 0; --b) inflatedSize = (inflatedSize << 8) | compressed.data[size - 4 + b];
  if (inflatedSize < needed || inflatedSize > kWholeInflateLimit) return {};
  Bytes inflated(inflatedSize);
  libdeflate_decompressor* decompressor = libdeflate_alloc_decompressor();
  if (!decompressor) return {};
  std::size_t used = 0, produced = 0;
  const libdeflate_result result = libdeflate_gzip_decompress_ex(
      decompressor, compressed.data.get(), compressed.size, inflated.data.get(), inflated.size, &used, &produced);
  libdeflate_free_decompressor(decompressor);
  if (result != LIBDEFLATE_SUCCESS || used != compressed.size || produced != inflated.size) return {};
  return inflated;
}

// checkNiftiFile, and with `voxels` given, readNiftiVoxels.
bool niftiFile(const std::string& path, std::vector<float>* voxels) {
  const bool gzipped = lowerCaseExtension(path) == ".gz";
  unsigned char header[540] = {};
  std::uintmax_t got = 0;
  if (gzipped) {
    gzFile file = gzopen(path.c_str(), "rb");
    if (!file) throw Error(path, "cannot be opened");
    const int read = gzread(file, header, sizeof header);
    gzclose(file);
    got = read > 0 ? static_cast<std::uintmax_t>(read) : 0;
  } else {
    std::ifstream in(path, std::ios::binary);
    in.read(reinterpret_cast<char*>(header), sizeof header);
    got = static_cast<std::uintmax_t>(in.gcount());
  }
  if (got < 348) throw Error(path, "not a NIfTI file: " + std::to_string(got) + " bytes, a header has 348");
  auto number = [&](int at, int bytes, bool swap) {
    std::uint64_t v = 0;
    for (int b = 0; b < bytes; ++b) v |= std::uint64_t{header[at + (swap ? bytes - 1 - b : b)]} << (8 * b);
    return v;
  };
  bool swap = false;
  int version = 0;
  for (const bool s : {false, true}) {
    const auto size = number(0, 4, s);
    if (size == 348) version = 1;
    if (size == 540) version = 2;
    if (version) {
      swap = s;
      break;
    }
  }
  if (!version) throw Error(path, "not a NIfTI file (its first four bytes give no header size of 348 or 540)");
  if (version == 2 && got < 540) throw Error(path, "truncated: a NIfTI-2 header of " + std::to_string(got) + " bytes");
  const int headerSize = version == 1 ? 348 : 540;
  // Offsets of dim[8], datatype and vox_offset in either version.
  const int dimAt = version == 1 ? 40 : 16, dimBytes = version == 1 ? 2 : 8;
  const auto datatype = static_cast<int>(static_cast<std::int16_t>(number(version == 1 ? 70 : 12, 2, swap)));
  auto dim = [&](int i) {
    const auto raw = number(dimAt + i * dimBytes, dimBytes, swap);
    return dimBytes == 2 ? static_cast<std::int64_t>(static_cast<std::int16_t>(raw)) : static_cast<std::int64_t>(raw);
  };
  const std::int64_t dimensions = dim(0);
  if (dimensions < 1 || dimensions > 7)
    throw Error(path, "a NIfTI header with " + std::to_string(dimensions) + " dimensions (1 to 7 are possible)");
  std::uintmax_t count = 1;
  for (int i = 1; i <= dimensions; ++i) {
    if (dim(i) < 1) throw Error(path, "a NIfTI header with size " + std::to_string(dim(i)) + " along axis " +
                                          std::to_string(i - 1));
    const auto next = product(count, static_cast<std::uintmax_t>(dim(i)));
    if (!next) throw Error(path, "a NIfTI header whose size does not fit in 64 bits");
    count = *next;
  }
  const int bytesPerVoxel = niftiBytesPerVoxel(datatype);
  if (!bytesPerVoxel) throw Error(path, "a NIfTI datatype " + std::to_string(datatype) + " that NIfTI does not define");
  requireMemoryFor(path, count);
  double offset = 0;
  if (version == 1) {
    const auto bits = static_cast<std::uint32_t>(number(108, 4, swap));
    float value = 0;
    std::memcpy(&value, &bits, sizeof value);
    offset = value;
  } else {
    offset = static_cast<double>(static_cast<std::int64_t>(number(168, 8, swap)));
  }
  if (!(offset >= headerSize) || offset > 1e12)
    throw Error(path, "a NIfTI header whose data offset (vox_offset " + std::to_string(offset) + ") is not after it");
  const auto needed = static_cast<std::uintmax_t>(offset) + count * bytesPerVoxel;
  std::array<std::int64_t, 3> size{1, 1, 1};
  for (int a = 0; a < 3 && a < dimensions; ++a) size[a] = dim(a + 1);
  // ITK reads the data of these as it is stored, then casts it to float:
  // NIfTI-1 in one file, three dimensions, a plain number type, no intensity
  // scaling and a whole data offset. Others (scaled, vectors, 4D, NIfTI-2) are
  // left to ITK.
  const StoredAsFloat convert = converterOf(datatype);
  const auto slopeBits = static_cast<std::uint32_t>(number(112, 4, swap)),
             interceptBits = static_cast<std::uint32_t>(number(116, 4, swap));
  float slope = 0, intercept = 0;
  std::memcpy(&slope, &slopeBits, sizeof slope);
  std::memcpy(&intercept, &interceptBits, sizeof intercept);
  const bool plain = voxels && version == 1 && std::memcmp(header + 344, "n+1", 4) == 0 && dimensions == 3 &&
                     convert && slope == 1.0f && intercept == 0.0f && offset == std::floor(offset);
  const bool floating = datatype == 16 || datatype == 64;
  // A plain .nii.gz is measured as it is read, below; the rest here.
  if (!plain || !gzipped) {
    const auto actual = gzipped ? inflatedSize(path, needed) : fs::file_size(path);
    if (actual < needed) throw truncatedData(path, actual, gzipped, needed);
  }
  if (!plain) {
    // ITK's NIfTI reader turns NaN and infinite voxels into 0 without a word
    // (measured with ITK 5.2): float data is scanned for them here.
    if (floating)
      requireFiniteVoxels(path, gzipped, static_cast<std::uintmax_t>(offset), count, datatype == 16 ? 4 : 8, swap,
                          size);
    return false;
  }
  // One pass: the data inflated whole, or else chunk by chunk, and converted.
  const Bytes whole = gzipped ? inflateWhole(path, needed) : Bytes();
  std::optional<DataReader> data;
  if (whole.empty()) data.emplace(path, gzipped, static_cast<std::uintmax_t>(offset));
  // Converted a chunk at a time into `converted`, in the cache, and appended:
  // a vector of `count` zeros first would write the whole image once more.
  std::vector<float> read;
  read.reserve(static_cast<std::size_t>(count));
  std::vector<float> converted(std::size_t{1} << 16);
  std::vector<unsigned char> chunk(static_cast<std::size_t>(bytesPerVoxel) << 16);
  std::uintmax_t done = 0, bad = 0, firstBad = 0;
  while (done < count) {
    const auto want = static_cast<std::size_t>(std::min<std::uintmax_t>(count - done, chunk.size() / bytesPerVoxel));
    const unsigned char* bytes = chunk.data();
    if (data) {
      const std::size_t got = data->read(chunk.data(), want * bytesPerVoxel);
      if (got < want * bytesPerVoxel)
        data->fail(static_cast<std::uintmax_t>(offset) + done * bytesPerVoxel + got, needed);
    } else {
      bytes = whole.data.get() + static_cast<std::size_t>(offset) + done * bytesPerVoxel;
    }
    float* out = converted.data();
    convert(bytes, want, swap, out);
    if (floating)
      for (std::size_t v = 0; v < want; ++v)
        if (!std::isfinite(out[v]) && bad++ == 0) firstBad = done + v;
    read.insert(read.end(), out, out + want);
    done += want;
  }
  // NaN stays NaN through the cast; a double beyond float's range becomes infinite.
  if (bad) throw Error(path, nonFiniteMessage(bad, firstBad, size));
  *voxels = std::move(read);
  return true;
}

}  // namespace

// NIfTI-1 (348-byte header) and NIfTI-2 (540), either byte order. ITK's reader
// fills a truncated .nii, or a .nii.gz whose gzip stream is cut short, with
// zeros without complaint, and allocates whatever the header announces.
void checkNiftiFile(const std::string& path) { niftiFile(path, nullptr); }

bool readNiftiVoxels(const std::string& path, std::vector<float>& voxels) { return niftiFile(path, &voxels); }

// ITK reads a short compressed .mha without complaint. Lists and patterns of
// slice files are left to ITK.
void checkMetaImageFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error(path, "cannot be opened");
  std::string line, dataFile, elementType;
  bool compressed = false;
  std::uintmax_t compressedSize = 0, channels = 1;
  std::vector<std::int64_t> size;
  long long dimensions = -1;
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
    if (key == "ElementDataFile") dataFile = value;
  }
  if (dataFile.empty()) throw Error(path, "a MetaImage header without ElementDataFile");
  if (dimensions < 1 || dimensions > 10)
    throw Error(path, "a MetaImage header with NDims " + std::to_string(dimensions) + " (1 to 10 are read)");
  if (static_cast<long long>(size.size()) != dimensions)
    throw Error(path, "MetaImage DimSize has " + std::to_string(size.size()) + " sizes for NDims " +
                          std::to_string(dimensions));
  std::uintmax_t voxels = 1;
  for (std::size_t a = 0; a < size.size(); ++a) {
    if (size[a] < 1)
      throw Error(path, "MetaImage DimSize " + std::to_string(size[a]) + " along axis " + std::to_string(a));
    const auto next = product(voxels, static_cast<std::uintmax_t>(size[a]));
    if (!next) throw Error(path, "a MetaImage header whose size does not fit in 64 bits");
    voxels = *next;
  }
  const int elementBytes = metaElementBytes(elementType);
  if (!elementBytes) throw Error(path, "MetaImage ElementType '" + elementType + "' is not one that is read");
  requireMemoryFor(path, voxels);
  const auto voxelBytes = product(voxels, channels * static_cast<std::uintmax_t>(elementBytes));
  if (!voxelBytes) throw Error(path, "a MetaImage header whose size does not fit in 64 bits");
  std::uintmax_t available = 0;
  std::string source = path;
  if (dataFile == "LOCAL") {
    const std::streamoff at = in.tellg();
    available = at < 0 ? 0 : fs::file_size(path) - static_cast<std::uintmax_t>(at);
  } else if (dataFile.find_first_of("% ") == std::string::npos && dataFile != "LIST") {
    source = (fs::path(path).parent_path() / dataFile).string();
    std::error_code error;
    available = fs::file_size(source, error);
    if (error) throw Error(path, "its data file " + source + " cannot be read");
  } else {
    return;
  }
  const std::uintmax_t needed = compressed ? compressedSize : *voxelBytes;
  if (available < needed)
    throw Error(source, "truncated: " + std::to_string(available) + " bytes of data, the header announces " +
                            std::to_string(needed));
}

// Whether a file says it is DICOM: "DICM" after the 128-byte preamble.
bool isDicomFile(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  char magic[4] = {};
  in.seekg(128);
  return in.read(magic, 4) && std::string(magic, 4) == "DICM";
}


bool walkDicomFile(const fs::path& file) { return DicomWalk(file).run(); }

bool isNiftiName(const std::string& path) {
  const std::string extension = lowerCaseExtension(path);
  return extension == ".nii" || (extension == ".gz" && lowerCaseExtension(path.substr(0, path.size() - 3)) == ".nii");
}

void checkImageFile(const std::string& path) {
  const std::string extension = lowerCaseExtension(path);
  if (isNiftiName(path)) checkNiftiFile(path);
  if (extension == ".mha" || extension == ".mhd") checkMetaImageFile(path);
}

}  // namespace dynsub::filechecks
