// readVolume reads the voxels of a plain NIfTI file itself, in the pass that
// checks the file (FileChecks.h: readNiftiVoxels), and takes the geometry
// from ITK's header reader. These tests hold it to what ITK's own reader
// gives, to the bit: every datatype it reads itself, both byte orders, plain
// and compressed, and the real MRI the demo segments; and files it leaves to
// ITK (scaled, 4D, other types) still read as ITK reads them.
#include <gtest/gtest.h>

#include <zlib.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <string>
#include <type_traits>
#include <vector>

#include "ScratchFiles.h"
#include "BridgeGeometry.h"
#include "FileChecks.h"
#include "ItkBridge.h"
#include "dynsub/ImageIO.h"

namespace dynsub {
namespace {

namespace fs = std::filesystem;

fs::path scratch(const std::string& name) { return scratchFile("NiftiVoxels", name); }

struct Layout {
  int datatype = 2;
  int bytes = 1;
  bool bigEndian = false;
  bool gzip = false;
  float slope = 1.0f, intercept = 0.0f;
  int dimensions = 3;  // dim[0]; dims 4.. are 1
  int members = 1;     // gzip members of a .nii.gz
};

// A NIfTI-1 file of 5 x 4 x 3 voxels with a rotated, anisotropic sform and
// qform, its data `data` (already in the file's byte order).
void writeNifti(const fs::path& path, const Layout& layout, const std::string& data) {
  std::string header(352, '\0');
  auto put = [&](std::size_t at, auto value) {
    char bytes[sizeof value];
    std::memcpy(bytes, &value, sizeof value);
    if (layout.bigEndian) std::reverse(bytes, bytes + sizeof value);
    std::memcpy(&header[at], bytes, sizeof value);
  };
  put(0, std::int32_t{348});
  put(40, static_cast<std::int16_t>(layout.dimensions));
  const std::int16_t dims[7] = {5, 4, 3, 1, 1, 1, 1};
  for (int a = 0; a < 7; ++a) put(42 + 2 * a, dims[a]);
  put(70, static_cast<std::int16_t>(layout.datatype));
  put(72, static_cast<std::int16_t>(8 * layout.bytes));
  const float spacing[3] = {0.8f, 1.25f, 2.0f};
  put(76, 1.0f);  // qfac
  for (int a = 0; a < 3; ++a) put(80 + 4 * a, spacing[a]);
  put(108, 352.0f);
  put(112, layout.slope);
  put(116, layout.intercept);
  header[123] = 10;  // mm, seconds
  put(252, std::int16_t{1});  // qform_code: scanner
  put(254, std::int16_t{1});  // sform_code: scanner
  // A rotation of 30 degrees about z, in both forms.
  const double c = std::cos(M_PI / 6), s = std::sin(M_PI / 6);
  put(256, 0.0f);  // quatern_b
  put(260, 0.0f);  // quatern_c
  put(264, static_cast<float>(std::sin(M_PI / 12)));  // quatern_d
  put(268, -12.5f);
  put(272, 30.25f);
  put(276, -7.0f);
  const double rows[3][4] = {{c * spacing[0], -s * spacing[1], 0, -12.5},
                             {s * spacing[0], c * spacing[1], 0, 30.25},
                             {0, 0, spacing[2], -7.0}};
  for (int r = 0; r < 3; ++r)
    for (int col = 0; col < 4; ++col) put(280 + 16 * r + 4 * col, static_cast<float>(rows[r][col]));
  std::memcpy(&header[344], "n+1\0", 4);
  const std::string file = header + data;
  if (layout.gzip) {
    // Two gzip members when asked (header, then data), as concatenated files are.
    const std::size_t split = layout.members == 2 ? header.size() : file.size();
    gzFile out = gzopen(path.c_str(), "wb");
    ASSERT_NE(out, nullptr);
    ASSERT_EQ(gzwrite(out, file.data(), static_cast<unsigned>(split)), static_cast<int>(split));
    gzclose(out);
    if (split < file.size()) {
      out = gzopen(path.c_str(), "ab");
      ASSERT_NE(out, nullptr);
      ASSERT_EQ(gzwrite(out, file.data() + split, static_cast<unsigned>(file.size() - split)),
                static_cast<int>(file.size() - split));
      gzclose(out);
    }
  } else {
    std::ofstream(path, std::ios::binary) << file;
  }
}

// 60 values of T in the file's byte order: the type's extremes, zero (and
// -0 for floats), and values a float cannot hold exactly (large int32,
// uint32 and double values, which the cast must round as ITK's does).
template <class T>
std::string values(bool bigEndian) {
  std::vector<T> v;
  v.push_back(std::numeric_limits<T>::lowest());
  v.push_back(std::numeric_limits<T>::max());
  v.push_back(T(0));
  if constexpr (std::is_floating_point_v<T>) {
    v.push_back(-T(0));
    v.push_back(std::numeric_limits<T>::denorm_min());
    v.push_back(T(0.1));
    v.push_back(T(-123456.789));
    if constexpr (sizeof(T) == 8) {
      v.push_back(T(16777217.0));  // between two floats: rounds
      v.push_back(T(3.0e38));      // within float's range
      v.push_back(T(1e-40));       // a float denormal
    }
  }
  if constexpr (std::is_integral_v<T> && sizeof(T) == 4) {
    v.push_back(T(16777217));  // rounds to a float
    v.push_back(T(2147483600));
  }
  for (int i = 0; static_cast<int>(v.size()) < 60; ++i) v.push_back(static_cast<T>((i * 37) % 101 - 50 * std::is_signed_v<T>));
  if constexpr (std::is_floating_point_v<T>) {
    // NaN and infinity are refused (another test); lowest and max of a double
    // are infinite as float: replaced by finite values for this one.
    if constexpr (sizeof(T) == 8) v[0] = T(-3.0e38), v[1] = T(3.0e38);
  }
  std::string bytes(v.size() * sizeof(T), '\0');
  for (std::size_t i = 0; i < v.size(); ++i) {
    char b[sizeof(T)];
    std::memcpy(b, &v[i], sizeof(T));
    if (bigEndian) std::reverse(b, b + sizeof(T));
    std::memcpy(&bytes[i * sizeof(T)], b, sizeof(T));
  }
  return bytes;
}

std::string valuesOf(int datatype, bool bigEndian) {
  switch (datatype) {
    case 2: return values<std::uint8_t>(bigEndian);
    case 256: return values<std::int8_t>(bigEndian);
    case 4: return values<std::int16_t>(bigEndian);
    case 512: return values<std::uint16_t>(bigEndian);
    case 8: return values<std::int32_t>(bigEndian);
    case 768: return values<std::uint32_t>(bigEndian);
    case 16: return values<float>(bigEndian);
    case 64: return values<double>(bigEndian);
    case 1024: return values<std::int64_t>(bigEndian);
    default: return {};
  }
}

// What ITK's reader gives for `path`, and what readVolume gives, are the same
// to the bit: voxels and geometry.
void expectReadAsItkReadsIt(const fs::path& path) {
  itkbridge::Geometry itkGeometry;
  std::vector<float> itkVoxels;
  itkbridge::functions().readImage(path.string(), itkGeometry, itkVoxels);
  const Volume volume = readVolume(path.string());
  ASSERT_EQ(volume.voxels.size(), itkVoxels.size()) << path;
  EXPECT_EQ(std::memcmp(volume.voxels.data(), itkVoxels.data(), itkVoxels.size() * sizeof(float)), 0) << path;
  const ImageGeometry expected = fromBridge(itkGeometry);
  EXPECT_EQ(volume.geometry.size, expected.size) << path;
  EXPECT_EQ(volume.geometry.spacing, expected.spacing) << path;
  EXPECT_EQ(volume.geometry.origin, expected.origin) << path;
  EXPECT_EQ(volume.geometry.direction, expected.direction) << path;
}

TEST(NiftiVoxels, EveryDatatypeReadsAsItkReadsIt) {
  const std::vector<std::pair<int, int>> types = {{2, 1},   {256, 1}, {4, 2},  {512, 2},
                                                  {8, 4},   {768, 4}, {16, 4}, {64, 8}};
  for (const auto& [datatype, bytes] : types)
    for (const bool bigEndian : {false, true})
      for (const bool gzip : {false, true}) {
        Layout layout;
        layout.datatype = datatype, layout.bytes = bytes, layout.bigEndian = bigEndian, layout.gzip = gzip;
        const fs::path path = scratch("type" + std::to_string(datatype) + (bigEndian ? "_big" : "_little") +
                                      (gzip ? ".nii.gz" : ".nii"));
        writeNifti(path, layout, valuesOf(datatype, bigEndian));
        std::vector<float> voxels;
        EXPECT_TRUE(filechecks::readNiftiVoxels(path.string(), voxels)) << path << " was left to ITK";
        expectReadAsItkReadsIt(path);
      }
}

// A .nii.gz of two gzip members is inflated by zlib's stream, not in one
// piece (which reads one member).
TEST(NiftiVoxels, AFileOfTwoGzipMembersReadsAsItkReadsIt) {
  Layout layout;
  layout.datatype = 4, layout.bytes = 2, layout.gzip = true, layout.members = 2;
  const fs::path path = scratch("two_members.nii.gz");
  writeNifti(path, layout, valuesOf(4, false));
  std::vector<float> voxels;
  EXPECT_TRUE(filechecks::readNiftiVoxels(path.string(), voxels));
  expectReadAsItkReadsIt(path);
}

TEST(NiftiVoxels, FilesLeftToItkReadAsBefore) {
  struct Case {
    std::string name;
    Layout layout;
  };
  std::vector<Case> cases(4);
  cases[0].name = "scaled.nii.gz", cases[0].layout.slope = 2.5f, cases[0].layout.intercept = -3.0f;
  cases[1].name = "offset.nii", cases[1].layout.intercept = 1.0f;
  cases[2].name = "int64.nii", cases[2].layout.datatype = 1024, cases[2].layout.bytes = 8;
  cases[3].name = "fourd.nii.gz", cases[3].layout.dimensions = 4;
  for (Case& c : cases) {
    c.layout.gzip = c.name.size() > 3 && c.name.substr(c.name.size() - 3) == ".gz";
    const fs::path path = scratch(c.name);
    writeNifti(path, c.layout, valuesOf(c.layout.datatype, false));
    std::vector<float> voxels;
    EXPECT_FALSE(filechecks::readNiftiVoxels(path.string(), voxels)) << c.name << " was read without ITK";
    EXPECT_TRUE(voxels.empty()) << c.name;
    expectReadAsItkReadsIt(path);
  }
}

TEST(NiftiVoxels, TheMriAndAtlasReadAsItkReadsThem) {
  // Colin27 and AAL (uint8, sform only), and the 0.5 mm Colin27 (qform only).
  for (const std::string name : {"ch2.nii.gz", "aal.nii.gz", "ch2better.nii.gz"}) {
    const fs::path path = fs::path("/usr/share/mricron/templates") / name;
    ASSERT_TRUE(fs::exists(path)) << path << " (Debian's mricron-data, installed by ./run)";
    std::vector<float> voxels;
    EXPECT_TRUE(filechecks::readNiftiVoxels(path.string(), voxels)) << path << " was left to ITK";
    expectReadAsItkReadsIt(path);
  }
}

}  // namespace
}  // namespace dynsub
