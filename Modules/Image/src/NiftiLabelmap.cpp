#include "NiftiLabelmap.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <fstream>
#include <memory>
#include <vector>

#include <Eigen/SVD>
#include <zlib.h>

#include "dynsub/AtomicOutput.h"
#include "dynsub/Error.h"
#include "dynsub/FileNames.h"

namespace dynsub {
namespace {

constexpr std::size_t kHeaderBytes = 348;
// The header and four zero bytes that say no extension follows.
constexpr std::size_t kVoxelOffset = 352;
// A labelmap is long runs of one value, mostly 0: zlib's run-length strategy
// (matches at distance 1 only) packs it a few per cent larger than zlib's
// default level, which ITK's writer uses, in about a third of the time
// (Documentation/Performance.md, "Outputs").
constexpr int kCompressionStrategy = Z_RLE;

// A buffer left uninitialized until written.
struct Bytes {
  std::unique_ptr<unsigned char[]> data;
  std::size_t size;
  explicit Bytes(std::size_t n) : data(new unsigned char[n]), size(n) {}
};

template <typename T>
void put(unsigned char* header, std::size_t at, T value) {
  std::memcpy(header + at, &value, sizeof(T));
}

// The NIfTI-1 fields, at their offsets (little-endian, as this machine
// stores them), for an unsigned 8-bit image on `g`. NIfTI is RAS: DynSub's
// LPS x and y change sign.
void writeHeader(unsigned char* file, const ImageGeometry& g) {
  put<std::int32_t>(file, 0, static_cast<std::int32_t>(kHeaderBytes));
  file[38] = 'r';  // regular, as ITK writes it
  const std::int16_t dim[8] = {3, static_cast<std::int16_t>(g.size[0]), static_cast<std::int16_t>(g.size[1]),
                               static_cast<std::int16_t>(g.size[2]), 1, 1, 1, 1};
  std::memcpy(file + 40, dim, sizeof dim);
  put<std::int16_t>(file, 70, 2);  // datatype: unsigned char
  put<std::int16_t>(file, 72, 8);  // bits per voxel
  const Eigen::Matrix3d lpsToRas = Eigen::Vector3d(-1, -1, 1).asDiagonal();
  Eigen::Matrix3d axes = lpsToRas * g.direction;  // columns: the i, j, k axes in RAS
  // The quaternion holds a rotation; a left-handed grid is a rotation with
  // the k axis negated, told by qfac = -1 (pixdim[0]).
  const float qfac = axes.determinant() < 0 ? -1.0f : 1.0f;
  axes.col(2) *= qfac;
  // The nearest rotation (polar decomposition), for axes stored to float
  // precision that are not quite orthonormal.
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(axes, Eigen::ComputeFullU | Eigen::ComputeFullV);
  const Eigen::Matrix3d r = svd.matrixU() * svd.matrixV().transpose();
  // Its quaternion (a, b, c, d), a >= 0 as NIfTI implies it, by the largest of
  // the four diagonal combinations (numerically safe for any rotation).
  double a, b, c, d;
  const double trace = r.trace();
  if (trace > 0) {
    const double s = 2 * std::sqrt(1 + trace);
    a = s / 4, b = (r(2, 1) - r(1, 2)) / s, c = (r(0, 2) - r(2, 0)) / s, d = (r(1, 0) - r(0, 1)) / s;
  } else if (r(0, 0) > r(1, 1) && r(0, 0) > r(2, 2)) {
    const double s = 2 * std::sqrt(1 + r(0, 0) - r(1, 1) - r(2, 2));
    a = (r(2, 1) - r(1, 2)) / s, b = s / 4, c = (r(0, 1) + r(1, 0)) / s, d = (r(0, 2) + r(2, 0)) / s;
  } else if (r(1, 1) > r(2, 2)) {
    const double s = 2 * std::sqrt(1 + r(1, 1) - r(0, 0) - r(2, 2));
    a = (r(0, 2) - r(2, 0)) / s, b = (r(0, 1) + r(1, 0)) / s, c = s / 4, d = (r(1, 2) + r(2, 1)) / s;
  } else {
    const double s = 2 * std::sqrt(1 + r(2, 2) - r(0, 0) - r(1, 1));
    a = (r(1, 0) - r(0, 1)) / s, b = (r(0, 2) + r(2, 0)) / s, c = (r(1, 2) + r(2, 1)) / s, d = s / 4;
  }
  if (a < 0) b = -b, c = -c, d = -d;
  const float pixdim[8] = {qfac, static_cast<float>(g.spacing.x()), static_cast<float>(g.spacing.y()),
                           static_cast<float>(g.spacing.z()), 0, 0, 0, 0};
  std::memcpy(file + 76, pixdim, sizeof pixdim);
  put<float>(file, 108, static_cast<float>(kVoxelOffset));
  put<float>(file, 112, 1.0f);  // scl_slope 1, scl_inter 0: the values as stored
  file[123] = 2;                // xyzt_units: mm
  put<std::int16_t>(file, 252, 1);  // qform_code: scanner-based anatomical
  put<std::int16_t>(file, 254, 1);  // sform_code: the same
  const Eigen::Vector3d origin = lpsToRas * g.origin;
  const float quaternion[6] = {static_cast<float>(b),        static_cast<float>(c),
                               static_cast<float>(d),        static_cast<float>(origin.x()),
                               static_cast<float>(origin.y()), static_cast<float>(origin.z())};
  std::memcpy(file + 256, quaternion, sizeof quaternion);
  // The affine itself (sform): voxel index -> RAS mm.
  const Eigen::Matrix3d toRas = lpsToRas * g.direction * g.spacing.asDiagonal();
  for (int row = 0; row < 3; ++row) {
    const float srow[4] = {static_cast<float>(toRas(row, 0)), static_cast<float>(toRas(row, 1)),
                           static_cast<float>(toRas(row, 2)), static_cast<float>(origin(row))};
    std::memcpy(file + 280 + 16 * row, srow, sizeof srow);
  }
  std::memcpy(file + 344, "n+1", 4);
}

// `size` bytes from `data` as one gzip member, or an error naming `path`.
// Fed to zlib in pieces: its counts are 32-bit.
std::vector<unsigned char> gzip(const unsigned char* data, std::size_t size, const std::string& path) {
  z_stream stream{};
  // 15 + 16: a 32 KiB window with a gzip header and trailer.
  if (deflateInit2(&stream, Z_DEFAULT_COMPRESSION, Z_DEFLATED, 15 + 16, 8, kCompressionStrategy) != Z_OK)
    throw Error(path, "cannot start compressing the labelmap (out of memory?)");
  const std::unique_ptr<z_stream, int (*)(z_stream*)> end(&stream, &deflateEnd);
  constexpr std::size_t kPiece = std::size_t{1} << 30;
  std::vector<unsigned char> packed;
  unsigned char buffer[1 << 16];
  int status = Z_OK;
  std::size_t fed = 0;
  while (status != Z_STREAM_END) {
    if (stream.avail_in == 0 && fed < size) {
      const std::size_t piece = std::min(kPiece, size - fed);
      stream.next_in = const_cast<unsigned char*>(data + fed);
      stream.avail_in = static_cast<uInt>(piece);
      fed += piece;
    }
    stream.next_out = buffer;
    stream.avail_out = sizeof buffer;
    status = deflate(&stream, fed == size ? Z_FINISH : Z_NO_FLUSH);
    if (status != Z_OK && status != Z_STREAM_END && status != Z_BUF_ERROR)
      throw Error(path, "the labelmap could not be compressed (zlib status " + std::to_string(status) + ")");
    packed.insert(packed.end(), buffer, buffer + (sizeof buffer - stream.avail_out));
  }
  return packed;
}

}  // namespace

void writeNiftiLabelmap(const Mask& mask, std::uint8_t label, const std::string& path) {
  const ImageGeometry& g = mask.geometry;
  for (int a = 0; a < 3; ++a)
    if (g.size[a] < 1 || g.size[a] > 32767)
      throw Error(path, "a grid of " + std::to_string(g.size[a]) + " voxels along axis " + std::to_string(a) +
                            " does not fit a NIfTI-1 header (1 to 32767)");
  const auto count = static_cast<std::size_t>(g.voxelCount());
  if (mask.voxels.size() != count)
    throw Error(path, "internal: a mask of " + std::to_string(mask.voxels.size()) + " voxels on a grid of " +
                          std::to_string(count) + "; nothing written");
  // The header zeroed, the voxels written once (a vector's resize would
  // zero them first), through plain pointers so that the loop vectorizes
  // (stores through unsigned char may alias anything, even a vector's own
  // members, which the compiler then reloads at every voxel).
  Bytes file(kVoxelOffset + count);
  std::memset(file.data.get(), 0, kVoxelOffset);
  writeHeader(file.data.get(), g);
  const std::uint8_t* mine = mask.voxels.data();
  unsigned char* voxels = file.data.get() + kVoxelOffset;
  for (std::size_t v = 0; v < count; ++v) voxels[v] = mine[v] ? label : 0;
  const bool compressed = lowerCaseExtension(path) == ".gz";
  const std::vector<unsigned char> gzipped = compressed ? gzip(file.data.get(), file.size, path)
                                                        : std::vector<unsigned char>();
  AtomicOutput output(path);
  std::ofstream out(output.temporaryPath(), std::ios::binary);
  if (compressed) {
    out.write(reinterpret_cast<const char*>(gzipped.data()), static_cast<std::streamsize>(gzipped.size()));
  } else {
    out.write(reinterpret_cast<const char*>(file.data.get()), static_cast<std::streamsize>(file.size));
  }
  out.close();
  if (!out) throw writeFailure(path);
  output.commit();
}

}  // namespace dynsub
