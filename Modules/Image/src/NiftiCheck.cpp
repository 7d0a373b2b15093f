// NIfTI files: the checks made before ITK reads them (FileChecks.h).
#include "FileChecks.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <vector>

#include <zlib.h>

#include "dynsub/Error.h"
#include "dynsub/FileNames.h"

namespace dynsub::filechecks {
namespace fs = std::filesystem;

namespace {

// A NIfTI-1 header's size, which its first four bytes state, and the size of
// its real numbers (floats).
constexpr int kHeaderBytes = 348;
constexpr int kRealBytes = 4;

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

// The error for `bad` NaN or infinite voxels, the first at index `first`.
std::string nonFiniteMessage(std::uintmax_t bad, std::uintmax_t first, const std::array<std::int64_t, 3>& size) {
  const std::uintmax_t i = first % size[0], j = first / size[0] % size[1], k = first / size[0] / size[1];
  return std::to_string(bad) + " voxel(s) are NaN or infinite, the first at index (" + std::to_string(i) + ", " +
         std::to_string(j) + ", " + std::to_string(k) + "); intensities must be finite";
}

// A NIfTI file whose data ends (`actual` bytes, inflated when gzipped) before
// the `needed` bytes its header announces.
Error truncatedData(const std::string& path, std::uintmax_t actual, bool gzipped, std::uintmax_t needed) {
  return Error(path, "truncated: " + std::to_string(actual) + (gzipped ? " bytes inflated" : " bytes") +
                         ", the header announces " + std::to_string(needed));
}

// Scans `voxels` float (4-byte) or double (8-byte) values from `data`;
// throws naming the count of NaN or infinite ones and the voxel index
// (i, j, k) of the first.
void requireFiniteVoxels(const std::string& path, const unsigned char* data, std::uintmax_t voxels, int bytes,
                         bool swap, const std::array<std::int64_t, 3>& size) {
  std::uintmax_t bad = 0, first = 0;
  for (std::uintmax_t v = 0; v < voxels; ++v) {
    unsigned char value[8];
    std::memcpy(value, data + v * bytes, bytes);
    if (swap) std::reverse(value, value + bytes);
    double number = 0;
    if (bytes == 4) {
      float f = 0;
      std::memcpy(&f, value, 4);
      number = f;
    } else {
      std::memcpy(&number, value, 8);
    }
    if (!std::isfinite(number) && bad++ == 0) first = v;
  }
  if (bad) throw Error(path, nonFiniteMessage(bad, first, size));
}

// The `count` bytes of a plain file from byte `offset`.
std::vector<unsigned char> readBytes(const std::string& path, std::uintmax_t offset, std::uintmax_t count) {
  std::ifstream in(path, std::ios::binary);
  std::vector<unsigned char> bytes(static_cast<std::size_t>(count));
  in.seekg(static_cast<std::streamoff>(offset));
  in.read(reinterpret_cast<char*>(bytes.data()), static_cast<std::streamsize>(count));
  if (!in) throw Error(path, "cannot read its voxels");
  return bytes;
}

// A header with both a qform and a sform, read as ITK reads it: ITK 5.2
// takes the sform only when its code is 1 (scanner) and its axes are
// perpendicular, and the qform otherwise. FSL and nibabel take the sform
// whenever its code is above 0. Where ITK takes the qform and the two place
// the image more than half a voxel apart, DynSub's outputs (which carry the
// placement ITK read) and points placed in FSL or nibabel would lie that far
// off each other: refused, saying by how much and which to change.
template <class Real>
void requireOnePlacement(const std::string& path, const Real& real, const std::array<std::int64_t, 3>& size,
                         int sformCode) {
  // sform: rows srow_x, srow_y, srow_z of 4 values each.
  const int srow = 280;
  double sform[3][4];
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 4; ++c) sform[r][c] = real(srow + (4 * r + c) * kRealBytes);
  double largestCosine = 0;
  for (int a = 0; a < 3; ++a)
    for (int b = a + 1; b < 3; ++b) {
      double dot = 0, na = 0, nb = 0;
      for (int r = 0; r < 3; ++r) {
        dot += sform[r][a] * sform[r][b];
        na += sform[r][a] * sform[r][a];
        nb += sform[r][b] * sform[r][b];
      }
      largestCosine = std::max(largestCosine, std::abs(dot) / std::sqrt(na * nb));
    }
  const bool sheared = largestCosine > 1e-4;
  if (!sheared && sformCode == 1) return;  // ITK takes the sform, as the others do
  // qform: quatern_b, c, d, qoffset_x, y, z, and pixdim[0..3] (qfac, spacing).
  const int quatern = 256, pixdim = 76;
  // As NIfTI's reference library reads them: b, c, d of a norm above 1 are
  // normalized (a = 0), and a spacing of 0 or less is taken as 1.
  double b = real(quatern), c = real(quatern + kRealBytes), d = real(quatern + 2 * kRealBytes);
  const double squared = b * b + c * c + d * d;
  if (squared > 1.0) {
    const double norm = std::sqrt(squared);
    b /= norm;
    c /= norm;
    d /= norm;
  }
  const double a = std::sqrt(std::max(0.0, 1.0 - (b * b + c * c + d * d)));
  auto positive = [](double spacing) { return spacing > 0 ? spacing : 1.0; };
  const double rotation[3][3] = {{a * a + b * b - c * c - d * d, 2 * (b * c - a * d), 2 * (b * d + a * c)},
                                 {2 * (b * c + a * d), a * a + c * c - b * b - d * d, 2 * (c * d - a * b)},
                                 {2 * (b * d - a * c), 2 * (c * d + a * b), a * a + d * d - c * c - b * b}};
  const double spacing[3] = {positive(real(pixdim + kRealBytes)), positive(real(pixdim + 2 * kRealBytes)),
                             (real(pixdim) < 0 ? -1.0 : 1.0) * positive(real(pixdim + 3 * kRealBytes))};
  // The largest distance between the two placements of a corner voxel.
  double apart = 0;
  for (int corner = 0; corner < 8; ++corner) {
    const double index[3] = {corner & 1 ? size[0] - 1.0 : 0.0, corner & 2 ? size[1] - 1.0 : 0.0,
                             corner & 4 ? size[2] - 1.0 : 0.0};
    double squared = 0;
    for (int r = 0; r < 3; ++r) {
      double bySform = sform[r][3], byQform = real(quatern + (3 + r) * kRealBytes);
      for (int k = 0; k < 3; ++k) {
        bySform += sform[r][k] * index[k];
        byQform += rotation[r][k] * spacing[k] * index[k];
      }
      squared += (bySform - byQform) * (bySform - byQform);
    }
    apart = std::max(apart, std::sqrt(squared));
  }
  const double smallestSpacing = std::min({std::abs(spacing[0]), std::abs(spacing[1]), std::abs(spacing[2])});
  if (!(apart > 0.5 * smallestSpacing)) return;
  char distance[32];
  std::snprintf(distance, sizeof distance, "%.1f", apart);
  if (sheared)
    throw Error(path, std::string("a NIfTI header whose sform is sheared (its axes are not perpendicular), which ITK "
                                  "cannot represent; its qform, which would be read instead, places the image up to ") +
                          distance +
                          " mm elsewhere. Resample the image onto a grid without shear, or set its sform_code to 0 "
                          "if the qform is the placement meant");
  throw Error(path,
              "a NIfTI header whose qform and sform place the image up to " + std::string(distance) +
                  " mm apart: ITK-based tools (DynSub, 3D Slicer, ITK-SNAP) read the qform, as the sform_code is " +
                  std::to_string(sformCode) +
                  " (not 1, scanner), while FSL and nibabel read the sform. Make the two agree (FSL: "
                  "fslorient -copysform2qform if the sform is the placement meant, -copyqform2sform if the "
                  "qform is)");
}

}  // namespace

// NIfTI-1 (a 348-byte header), either byte order. ITK's reader fills a
// truncated .nii, or a .nii.gz whose gzip stream is cut short, with zeros
// without complaint, and allocates whatever the header announces. ITK 5.2
// does not read NIfTI-2 (a 540-byte header): such a file is named as one.
DataCheck checkNiftiHeader(const std::string& path) {
  // Compressed or not by its first bytes, as ITK's reader (zlib) takes a
  // .nii.gz that is not compressed; it reads a .nii by its name alone.
  unsigned char magic[2] = {};
  std::ifstream(path, std::ios::binary).read(reinterpret_cast<char*>(magic), 2);
  const bool gzipped = magic[0] == 0x1f && magic[1] == 0x8b;
  if (gzipped && lowerCaseExtension(path) != ".gz")
    throw Error(path, "compressed with gzip, but named as an uncompressed NIfTI file: name it .nii.gz");
  unsigned char header[kHeaderBytes] = {};
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
  if (got < kHeaderBytes)
    throw Error(path,
                "not a NIfTI file: " + std::to_string(got) + " bytes, a header has " + std::to_string(kHeaderBytes));
  auto number = [&](int at, int bytes, bool swap) {
    std::uint64_t v = 0;
    for (int b = 0; b < bytes; ++b) v |= std::uint64_t{header[at + (swap ? bytes - 1 - b : b)]} << (8 * b);
    return v;
  };
  const bool swap = number(0, 4, false) != kHeaderBytes;
  if (number(0, 4, swap) != kHeaderBytes) {
    if (number(0, 4, false) == 540 || number(0, 4, true) == 540)
      throw Error(path,
                  "a NIfTI-2 file, which ITK 5.2 (DynSub's image reader) does not read: save it as NIfTI-1 "
                  "(nibabel: nibabel.Nifti1Image; FSL and SPM write NIfTI-1)");
    throw Error(path, "not a NIfTI file (its first four bytes give no header size of 348)");
  }
  const auto datatype = static_cast<int>(static_cast<std::int16_t>(number(70, 2, swap)));
  auto dim = [&](int i) { return static_cast<std::int64_t>(static_cast<std::int16_t>(number(40 + 2 * i, 2, swap))); };
  const std::int64_t dimensions = dim(0);
  if (dimensions < 1 || dimensions > 7)
    throw Error(path, "a NIfTI header with " + std::to_string(dimensions) + " dimensions (1 to 7 are possible)");
  std::uintmax_t count = 1;
  for (int i = 1; i <= dimensions; ++i) {
    if (dim(i) < 1) throw Error(path, "a NIfTI header with size " + std::to_string(dim(i)) + " along axis " +
                                          std::to_string(i - 1));
    const auto next = checkedProduct(count, static_cast<std::uintmax_t>(dim(i)));
    if (!next) throw Error(path, "a NIfTI header whose size does not fit in 64 bits");
    count = *next;
  }
  const int bytesPerVoxel = niftiBytesPerVoxel(datatype);
  if (!bytesPerVoxel) throw Error(path, "a NIfTI datatype " + std::to_string(datatype) + " that NIfTI does not define");
  // Intensities are one real number a voxel; ITK would read complex or
  // colour voxels as something else without a word.
  if (datatype == 32 || datatype == 1792 || datatype == 2048 || datatype == 128 || datatype == 2304)
    throw Error(path, std::string("a NIfTI image of ") +
                          (datatype == 128 || datatype == 2304 ? "colour (RGB)" : "complex") +
                          " voxels; give one real value a voxel (a magnitude or grey-level image)");
  // A series of volumes (fMRI, diffusion) is not one 3D image; read as one,
  // ITK 5.2 also takes another orientation.
  for (int i = 4; i <= dimensions; ++i) {
    if (dim(i) > 1)
      throw Error(path, "a NIfTI image of " + std::to_string(dimensions) + " dimensions, " + std::to_string(dim(i)) +
                            " along axis " + std::to_string(i - 1) + "; give one 3D volume (extract it first)");
  }
  // A header's real number (a float) at byte `at`.
  auto real = [&](int at) {
    const auto bits = static_cast<std::uint32_t>(number(at, 4, swap));
    float value = 0;
    std::memcpy(&value, &bits, sizeof value);
    return static_cast<double>(value);
  };
  // The orientation the header declares (qform, sform: whichever has a
  // code above 0) must be finite: ITK 5.2 aborts the process on a NaN there.
  auto code = [&](int at) { return static_cast<int>(static_cast<std::int16_t>(number(at, 2, swap))); };
  const int qformCode = code(252), sformCode = code(254);
  auto requireFinite = [&](int first, int count, const char* what) {
    for (int i = 0; i < count; ++i) {
      if (!std::isfinite(real(first + i * kRealBytes)))
        throw Error(path, std::string("a NIfTI header whose ") + what + " holds a NaN or infinite value");
    }
  };
  if (qformCode > 0) requireFinite(256, 6, "qform (quatern_b-d, qoffset_x-z)");
  if (sformCode > 0) requireFinite(280, 12, "sform (srow_x, srow_y, srow_z)");
  std::array<std::int64_t, 3> size{1, 1, 1};
  for (int a = 0; a < 3 && a < dimensions; ++a) size[a] = dim(a + 1);
  if (qformCode > 0 && sformCode > 0) requireOnePlacement(path, real, size, sformCode);
  requireMemoryFor(path, count);
  const double offset = real(108);  // vox_offset
  if (!(offset >= kHeaderBytes) || offset > 1e12)
    throw Error(path, "a NIfTI header whose data offset (vox_offset " + std::to_string(offset) + ") is not after it");
  const auto needed = static_cast<std::uintmax_t>(offset) + count * bytesPerVoxel;
  DataCheck checkData = [=] {
    // The whole stream is inflated: a gzip stream cut short or corrupt after
    // the image's bytes is refused too.
    const std::vector<unsigned char> inflated = gzipped ? inflateGzipFile(path, needed) : std::vector<unsigned char>();
    const auto actual = gzipped ? inflated.size() : fs::file_size(path);
    if (actual < needed) throw truncatedData(path, actual, gzipped, needed);
    // ITK's NIfTI reader turns NaN and infinite voxels into 0 without a word
    // (ITK 5.2): float data is scanned for them here.
    if (datatype == 16 || datatype == 64) {
      const int bytes = datatype == 16 ? 4 : 8;
      const auto start = static_cast<std::uintmax_t>(offset);
      const std::vector<unsigned char> plain =
          gzipped ? std::vector<unsigned char>() : readBytes(path, start, count * bytes);
      requireFiniteVoxels(path, gzipped ? inflated.data() + start : plain.data(), count, bytes, swap, size);
    }
  };
  // A file too small to hold the data its header announces (inflated, a
  // deflate stream grows at most 1032-fold) is refused now, before any reader
  // allocates the announced image.
  const std::uintmax_t fileSize = fs::file_size(path);
  const auto reach = gzipped ? checkedProduct(fileSize, kLargestDeflateRatio) : std::optional<std::uintmax_t>(fileSize);
  if (reach && *reach < needed) checkData();
  return checkData;
}

bool isNiftiName(const std::string& path) {
  const std::string extension = lowerCaseExtension(path);
  return extension == ".nii" || (extension == ".gz" && lowerCaseExtension(path.substr(0, path.size() - 3)) == ".nii");
}

}  // namespace dynsub::filechecks
