#include <gtest/gtest.h>

#include <limits>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>

#include "dynsub/EdgePotential.h"
#include "dynsub/Error.h"
#include "dynsub/ImageIO.h"
#include "dynsub/Metrics.h"
#include "dynsub/Voxelize.h"

namespace dynsub {
namespace {

namespace fs = std::filesystem;

// A rotation about a skew axis: no axis of the grid is aligned with LPS.
Matrix3 skewDirection() {
  return Eigen::AngleAxisd(0.5, Vector3(1, 2, 3).normalized()).toRotationMatrix();
}

ImageGeometry grid(std::array<int, 3> size, Vector3 spacing, Vector3 origin, Matrix3 direction) {
  ImageGeometry g;
  g.size = size;
  g.spacing = spacing;
  g.origin = origin;
  g.direction = direction;
  return g;
}

fs::path scratch(const std::string& name) {
  const fs::path dir = fs::path(DYNSUB_BINARY_DIR) / "Testing" / "Temporary" / "Image";
  fs::create_directories(dir);
  return dir / name;
}

// A closed UV sphere (triangles oriented outward).
void uvSphere(const Vector3& centre, double radius, Matrix3X& points, std::vector<std::array<int, 3>>& triangles) {
  const int rings = 60, sectors = 120;
  points.resize(2 + (rings - 1) * sectors, 3);
  points.row(0) = (centre + Vector3(0, 0, radius)).transpose();
  points.row(1) = (centre - Vector3(0, 0, radius)).transpose();
  for (int r = 1; r < rings; ++r)
    for (int s = 0; s < sectors; ++s) {
      const double theta = M_PI * r / rings, phi = 2 * M_PI * s / sectors;
      points.row(2 + (r - 1) * sectors + s) =
          (centre + radius * Vector3(std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi),
                                     std::cos(theta)))
              .transpose();
    }
  auto at = [&](int r, int s) { return 2 + (r - 1) * sectors + (s % sectors); };
  triangles.clear();
  for (int s = 0; s < sectors; ++s) {
    triangles.push_back({0, at(1, s), at(1, s + 1)});
    triangles.push_back({1, at(rings - 1, s + 1), at(rings - 1, s)});
    for (int r = 1; r + 1 < rings; ++r) {
      triangles.push_back({at(r, s), at(r + 1, s), at(r + 1, s + 1)});
      triangles.push_back({at(r, s), at(r + 1, s + 1), at(r, s + 1)});
    }
  }
}

TEST(ImageGeometry, IndexAndPhysicalAreInverse) {
  const ImageGeometry g = grid({10, 20, 30}, Vector3(0.5, 1.0, 2.0), Vector3(-3, 4, 5), skewDirection());
  const Vector3 index(1.5, -2.25, 7.0);
  EXPECT_LT((g.toIndex(g.toPhysical(index)) - index).norm(), 1e-12);
  // One step along k moves 2 mm along the direction's third column.
  EXPECT_LT((g.toPhysical(Vector3(0, 0, 1)) - g.origin - 2.0 * g.direction.col(2)).norm(), 1e-12);
}

TEST(ImageIO, MaskRoundTripKeepsGeometryAndVoxels) {
  Mask mask{grid({7, 5, 4}, Vector3(0.7, 1.1, 2.5), Vector3(12, -30, 8), skewDirection()), {}};
  mask.voxels.resize(mask.geometry.voxelCount());
  for (std::size_t v = 0; v < mask.voxels.size(); ++v) mask.voxels[v] = (v * 7919) % 3 == 0;
  // Every single-file format (the size checks of truncated files must pass whole ones).
  for (const std::string name : {"roundtrip.nii.gz", "roundtrip.nii", "roundtrip.nrrd", "roundtrip.mha"}) {
    const fs::path path = scratch(name);
    writeMask(mask, path.string());
    const Volume read = readVolume(path.string());
    EXPECT_EQ(read.geometry.size, mask.geometry.size) << name;
    // NIfTI stores spacing and the affine in single precision.
    EXPECT_LT((read.geometry.spacing - mask.geometry.spacing).norm(), 1e-5) << name;
    EXPECT_LT((read.geometry.origin - mask.geometry.origin).norm(), 1e-4) << name;
    EXPECT_LT((read.geometry.direction - mask.geometry.direction).norm(), 1e-5) << name;
    for (std::size_t v = 0; v < mask.voxels.size(); ++v) ASSERT_EQ(read.voxels[v], mask.voxels[v]) << name << v;
  }
}

// A MetaImage header with its voxels in a separate raw file, as other tools
// write it (writeMask refuses to: its header would name a temporary file).
TEST(ImageIO, MetaImageWithADataFile) {
  const fs::path header = scratch("detached.mhd"), data = scratch("detached.raw");
  std::ofstream(header) << "ObjectType = Image\nNDims = 3\nBinaryData = True\nBinaryDataByteOrderMSB = False\n"
                           "CompressedData = False\nTransformMatrix = 1 0 0 0 1 0 0 0 1\nOffset = 3 -2 1\n"
                           "ElementSpacing = 0.5 1 2\nDimSize = 4 3 2\nElementType = MET_UCHAR\n"
                           "ElementDataFile = detached.raw\n";
  std::string voxels;
  for (int v = 0; v < 24; ++v) voxels.push_back(static_cast<char>(v));
  std::ofstream(data, std::ios::binary) << voxels;
  const Volume read = readVolume(header.string());
  EXPECT_EQ(read.geometry.size, (std::array<int, 3>{4, 3, 2}));
  EXPECT_LT((read.geometry.spacing - Vector3(0.5, 1, 2)).norm(), 1e-12);
  EXPECT_LT((read.geometry.origin - Vector3(3, -2, 1)).norm(), 1e-12);
  for (int v = 0; v < 24; ++v) ASSERT_EQ(read.voxels[v], v);
  // The data file cut short: refused, naming it.
  fs::resize_file(data, 20);
  try {
    readVolume(header.string());
    ADD_FAILURE() << "a short data file was read";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("detached.raw: truncated"), std::string::npos) << e.what();
  }
  Mask mask{read.geometry, std::vector<std::uint8_t>(24, 1)};
  EXPECT_THROW(writeMask(mask, scratch("written.mhd").string()), Error);
  EXPECT_FALSE(fs::exists(scratch("written.mhd")));
}

TEST(ImageIO, BadFilesAreRefusedWithTheirName) {
  EXPECT_THROW(readVolume(scratch("missing.nii.gz").string()), Error);
  // One slice: not a 3D image.
  Mask slice{grid({8, 8, 1}, Vector3::Ones(), Vector3::Zero(), Matrix3::Identity()), {}};
  slice.voxels.assign(64, 1);
  writeMask(slice, scratch("slice.nii.gz").string());
  try {
    readVolume(scratch("slice.nii.gz").string());
    FAIL() << "a single slice was read as a volume";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("not a 3D image"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("slice.nii.gz"), std::string::npos) << e.what();
  }
  // Truncated: the header survives, the voxels do not. The voxels are
  // pseudo-random so that compressed files are large enough for their header
  // to survive a cut to 3/4 (a .nii.gz cut short used to read as zeros).
  Mask big{grid({40, 40, 40}, Vector3::Ones(), Vector3::Zero(), Matrix3::Identity()), {}};
  big.voxels.resize(big.geometry.voxelCount());
  unsigned state = 1;
  for (auto& voxel : big.voxels) voxel = ((state = state * 1103515245u + 12345u) >> 16) & 1u;
  for (const std::string name : {"whole.nii", "whole.nii.gz", "whole.nrrd", "whole.mha"}) {
    const fs::path whole = scratch(name);
    writeMask(big, whole.string());
    fs::resize_file(whole, fs::file_size(whole) * 3 / 4);
    try {
      readVolume(whole.string());
      ADD_FAILURE() << name << " cut to 3/4 was read";
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find(name), std::string::npos) << e.what();
    }
  }
  std::ofstream(scratch("text.nii").string()) << "not an image\n";
  EXPECT_THROW(readVolume(scratch("text.nii").string()), Error);
}

// ---- Hostile numbers in image files: a clear error or a correct volume ----

// A NIfTI-1 file of float voxels, written byte by byte (the header fields
// DynSub and ITK read): `dims` may be larger than the voxels written, to make
// a header that lies.
void writeNifti(const fs::path& path, std::array<long, 3> dims, Vector3 spacing, const std::vector<float>& voxels,
                double srowScale = 1.0) {
  std::string header(352, '\0');
  auto put = [&header](std::size_t at, auto value) { std::memcpy(&header[at], &value, sizeof value); };
  put(0, std::int32_t{348});
  put(40, std::int16_t{3});
  for (int a = 0; a < 3; ++a) put(42 + 2 * a, static_cast<std::int16_t>(std::min<long>(dims[a], 32767)));
  put(70, std::int16_t{16});  // float32
  put(72, std::int16_t{32});
  put(76, 1.0f);
  for (int a = 0; a < 3; ++a) put(80 + 4 * a, static_cast<float>(spacing[a]));
  put(108, 352.0f);
  put(112, 1.0f);  // scl_slope
  header[123] = 10;  // mm, seconds
  put(254, std::int16_t{1});  // sform_code: scanner
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 4; ++c) put(280 + 16 * r + 4 * c, static_cast<float>(r == c ? srowScale * spacing[r] : 0.0));
  std::memcpy(&header[344], "n+1\0", 4);
  std::ofstream out(path, std::ios::binary);
  out << header;
  out.write(reinterpret_cast<const char*>(voxels.data()), static_cast<std::streamsize>(voxels.size() * sizeof(float)));
}

std::vector<float> ramp(std::size_t n, float scale) {
  std::vector<float> voxels(n);
  for (std::size_t v = 0; v < n; ++v) voxels[v] = scale * static_cast<float>(v % 17);
  return voxels;
}

// The error readVolume gives for `path`, or "" when it reads it.
std::string readError(const fs::path& path) {
  try {
    readVolume(path.string());
    return "";
  } catch (const Error& e) {
    return e.what();
  }
}

TEST(HostileImages, NanAndInfiniteVoxelsAreRefusedWithTheFirstIndex) {
  for (const float bad : {std::numeric_limits<float>::quiet_NaN(), -std::numeric_limits<float>::infinity()}) {
    std::vector<float> voxels = ramp(6 * 5 * 4, 1.0f);
    voxels[2 + 6 * (3 + 5 * 1)] = bad;
    voxels[100] = bad;
    writeNifti(scratch("bad_voxels.nii"), {6, 5, 4}, Vector3(1, 1, 1), voxels);
    const std::string error = readError(scratch("bad_voxels.nii"));
    EXPECT_NE(error.find("bad_voxels.nii: 2 voxel(s) are NaN or infinite, the first at index (2, 3, 1)"),
              std::string::npos)
        << error;
  }
}

// ITK keeps NaN in MetaImage and NRRD files; readVolume refuses them there too.
TEST(HostileImages, NanVoxelsInMetaImageAndNrrdFilesAreRefused) {
  std::vector<float> voxels = ramp(4 * 3 * 2, 1.0f);
  voxels[7] = std::numeric_limits<float>::quiet_NaN();
  const std::string data(reinterpret_cast<const char*>(voxels.data()), voxels.size() * sizeof(float));
  std::ofstream(scratch("nan.mha"), std::ios::binary)
      << "ObjectType = Image\nNDims = 3\nDimSize = 4 3 2\nElementType = MET_FLOAT\nElementDataFile = LOCAL\n" << data;
  std::ofstream(scratch("nan.nrrd"), std::ios::binary)
      << "NRRD0004\ntype: float\ndimension: 3\nsizes: 4 3 2\nencoding: raw\nendian: little\n\n" << data;
  for (const std::string name : {"nan.mha", "nan.nrrd"}) {
    const std::string error = readError(scratch(name));
    EXPECT_NE(error.find(name + ": 1 voxel(s) are NaN or infinite, the first at index (3, 1, 0)"), std::string::npos)
        << error;
  }
}

TEST(HostileImages, ConstantAndExtremeIntensitiesAreReadExactly) {
  // The ramp goes up to 16 times the scale: 2.4e38 of float's 3.4e38.
  for (const float scale : {0.0f, 1.5e37f, 1e-37f, -1.5e37f}) {
    const std::vector<float> voxels = scale == 0.0f ? std::vector<float>(60, 42.0f) : ramp(60, scale);
    writeNifti(scratch("extreme.nii"), {5, 4, 3}, Vector3(1, 1, 1), voxels);
    const Volume volume = readVolume(scratch("extreme.nii").string());
    ASSERT_EQ(volume.voxels.size(), voxels.size());
    for (std::size_t v = 0; v < voxels.size(); ++v) ASSERT_EQ(volume.voxels[v], voxels[v]) << "scale " << scale;
  }
}

TEST(HostileImages, SpacingOutsideWhatDynSubWorksWithIsRefused) {
  for (const double spacing : {1e-6, 1e5}) {
    writeNifti(scratch("spacing.nii"), {4, 4, 4}, Vector3(1, spacing, 1), ramp(64, 1.0f));
    const std::string error = readError(scratch("spacing.nii"));
    EXPECT_NE(error.find("spacing.nii: voxel spacing"), std::string::npos) << error;
    EXPECT_NE(error.find("outside the 0.0001 to 10000 mm"), std::string::npos) << error;
  }
  // Near the limits (NIfTI stores spacing as float: 1e-4 itself reads as 9.99999975e-5).
  writeNifti(scratch("spacing.nii"), {4, 4, 4}, Vector3(2e-4, 1, 5e3), ramp(64, 1.0f));
  EXPECT_EQ(readError(scratch("spacing.nii")), "");
}

TEST(HostileImages, ADegenerateDirectionIsRefused) {
  // NRRD space directions with two parallel axes.
  std::ofstream(scratch("parallel.nrrd"), std::ios::binary)
      << "NRRD0004\ntype: float\ndimension: 3\nspace: left-posterior-superior\nsizes: 2 2 2\n"
         "space directions: (1,0,0) (0,1,0) (1,0,0)\nencoding: raw\nendian: little\nspace origin: (0,0,0)\n\n"
      << std::string(32, '\0');
  const std::string error = readError(scratch("parallel.nrrd"));
  EXPECT_NE(error.find("parallel.nrrd"), std::string::npos) << error;
  EXPECT_FALSE(error.empty());
}

TEST(HostileImages, HeadersAnnouncingHugeImagesAreRefusedBeforeAllocating) {
  // 1000^3 float voxels (4 GB) announced by a file of a few bytes: truncated.
  writeNifti(scratch("huge.nii"), {1000, 1000, 1000}, Vector3(1, 1, 1), ramp(8, 1.0f));
  std::string error = readError(scratch("huge.nii"));
  EXPECT_NE(error.find("huge.nii: truncated"), std::string::npos) << error;
  // 32767^3 (1.3e5 GiB): more than any memory, in NIfTI, MetaImage and NRRD
  // (the last through ITK's header reader).
  writeNifti(scratch("huge.nii"), {32767, 32767, 32767}, Vector3(1, 1, 1), ramp(8, 1.0f));
  error = readError(scratch("huge.nii"));
  EXPECT_NE(error.find("huge.nii: the header announces 35181150961663 voxels"), std::string::npos) << error;
  EXPECT_NE(error.find("GiB of memory"), std::string::npos) << error;
  std::ofstream(scratch("huge.mha"), std::ios::binary)
      << "ObjectType = Image\nNDims = 3\nDimSize = 100000 100000 100000\nElementType = MET_FLOAT\n"
         "ElementDataFile = LOCAL\n" << std::string(64, '\0');
  error = readError(scratch("huge.mha"));
  EXPECT_NE(error.find("huge.mha: the header announces 1000000000000000 voxels"), std::string::npos) << error;
  std::ofstream(scratch("huge.nrrd"), std::ios::binary)
      << "NRRD0004\ntype: float\ndimension: 3\nsizes: 100000 100000 100000\nencoding: raw\nendian: little\n\n"
      << std::string(64, '\0');
  error = readError(scratch("huge.nrrd"));
  EXPECT_NE(error.find("huge.nrrd: the header announces 1000000000000000 voxels"), std::string::npos) << error;
}

TEST(Voxelize, SphereOnAnAnisotropicRotatedGrid) {
  const ImageGeometry g = grid({48, 40, 24}, Vector3(0.6, 0.8, 1.5), Vector3(-14, -15, -16), skewDirection());
  const Vector3 centre = g.toPhysical(Vector3(23.5, 19.5, 11.5));
  const double radius = 10.0;
  Matrix3X points;
  std::vector<std::array<int, 3>> triangles;
  uvSphere(centre, radius, points, triangles);
  const Mask mask = voxelizeSurface(points, triangles, g);
  // Every voxel centre clearly inside or outside the sphere is classified so;
  // the polygon lies within radius (1 - cos(pi/60)) ~ 0.014 mm of the sphere.
  long long inside = 0;
  for (int k = 0; k < g.size[2]; ++k)
    for (int j = 0; j < g.size[1]; ++j)
      for (int i = 0; i < g.size[0]; ++i) {
        const double r = (g.toPhysical(Vector3(i, j, k)) - centre).norm();
        const bool set = mask.voxels[g.offset(i, j, k)];
        if (r < radius - 0.02) {
          ASSERT_TRUE(set) << i << ' ' << j << ' ' << k;
        }
        if (r > radius + 0.02) {
          ASSERT_FALSE(set) << i << ' ' << j << ' ' << k;
        }
        inside += set;
      }
  const double volume = inside * g.spacing.prod(), exact = 4.0 / 3.0 * M_PI * radius * radius * radius;
  EXPECT_NEAR(volume / exact, 1.0, 0.02);
}

TEST(Voxelize, OpenSurfaceIsRefused) {
  const ImageGeometry g = grid({20, 20, 20}, Vector3::Ones(), Vector3::Zero(), Matrix3::Identity());
  Matrix3X points;
  std::vector<std::array<int, 3>> triangles;
  uvSphere(Vector3(10, 10, 10), 5, points, triangles);
  triangles.pop_back();
  EXPECT_THROW(voxelizeSurface(points, triangles, g), Error);
}

Mask box(const ImageGeometry& g, std::array<int, 3> first, std::array<int, 3> last) {
  Mask m{g, std::vector<std::uint8_t>(g.voxelCount(), 0)};
  for (int k = first[2]; k <= last[2]; ++k)
    for (int j = first[1]; j <= last[1]; ++j)
      for (int i = first[0]; i <= last[0]; ++i) m.voxels[g.offset(i, j, k)] = 1;
  return m;
}

TEST(Metrics, ShiftedCubesByHand) {
  // Two 10^3 cubes, the second shifted by one voxel (0.5 mm) along i.
  const ImageGeometry g = grid({16, 14, 14}, Vector3(0.5, 1.0, 2.0), Vector3::Zero(), Matrix3::Identity());
  const Mask a = box(g, {2, 2, 2}, {11, 11, 11}), b = box(g, {3, 2, 2}, {12, 11, 11});
  const OverlapMetrics m = compareMasks(a, b);
  EXPECT_DOUBLE_EQ(m.dice, 2.0 * 900 / 2000);
  EXPECT_DOUBLE_EQ(m.jaccard, 900.0 / 1100);
  EXPECT_DOUBLE_EQ(m.volumeDifferencePercent, 0.0);
  EXPECT_DOUBLE_EQ(m.volumeA, 1000 * 1.0);
  // Of each cube's 488 boundary voxels, 164 lie one voxel (0.5 mm) from the
  // other's boundary (its whole leading face and the 8 x 8 inside of its
  // trailing face); the rest are on it.
  EXPECT_NEAR(m.meanSurfaceDistance, 0.5 * 164.0 / 488.0, 1e-6);
  EXPECT_NEAR(m.hausdorff, 0.5, 1e-6);
  EXPECT_NEAR(m.hd95, 0.5, 1e-6);

  const OverlapMetrics same = compareMasks(a, a);
  EXPECT_DOUBLE_EQ(same.dice, 1.0);
  EXPECT_DOUBLE_EQ(same.hausdorff, 0.0);
  const Mask smaller = box(g, {2, 2, 2}, {6, 11, 11});
  EXPECT_DOUBLE_EQ(compareMasks(smaller, a).volumeDifferencePercent, -50.0);
  EXPECT_THROW(compareMasks(box(g, {0, 0, 0}, {-1, -1, -1}), a), Error);
}

// The surface distances are computed on the box around both masks (Metrics.cpp);
// against brute force over every pair of boundary voxels, for masks far from
// the border, touching it, and far apart, on an anisotropic grid.
TEST(Metrics, SurfaceDistancesAgreeWithBruteForce) {
  const ImageGeometry g = grid({24, 20, 18}, Vector3(0.7, 1.0, 1.3), Vector3::Zero(), Matrix3::Identity());
  auto boundary = [&](const Mask& m) {
    std::vector<Vector3> points;
    for (int k = 0; k < g.size[2]; ++k)
      for (int j = 0; j < g.size[1]; ++j)
        for (int i = 0; i < g.size[0]; ++i) {
          if (!m.voxels[g.offset(i, j, k)]) continue;
          bool edge = false;
          for (const auto& [a, b, c] : {std::array<int, 3>{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}}) {
            edge = edge || !g.contains(i + a, j + b, k + c) || !m.voxels[g.offset(i + a, j + b, k + c)];
          }
          if (edge) points.push_back(g.toPhysical(Vector3(i, j, k)));
        }
    return points;
  };
  const std::vector<std::pair<Mask, Mask>> cases = {
      {box(g, {5, 5, 5}, {12, 11, 10}), box(g, {7, 4, 6}, {14, 12, 9})},
      {box(g, {0, 0, 3}, {9, 8, 17}), box(g, {2, 1, 0}, {11, 19, 12})},
      {box(g, {1, 2, 2}, {4, 5, 5}), box(g, {18, 14, 12}, {23, 19, 16})}};
  for (const auto& [a, b] : cases) {
    const std::vector<Vector3> ba = boundary(a), bb = boundary(b);
    std::vector<double> distances;
    for (const auto& [from, to] : {std::pair{&ba, &bb}, std::pair{&bb, &ba}}) {
      for (const Vector3& p : *from) {
        double nearest = 1e300;
        for (const Vector3& q : *to) nearest = std::min(nearest, (p - q).norm());
        distances.push_back(nearest);
      }
    }
    double sum = 0.0;
    for (double d : distances) sum += d;
    std::sort(distances.begin(), distances.end());
    const OverlapMetrics m = compareMasks(a, b);
    // Maurer's transform is exact; the distances are stored as float.
    EXPECT_NEAR(m.meanSurfaceDistance, sum / distances.size(), 1e-5);
    EXPECT_NEAR(m.hausdorff, distances.back(), 1e-5);
    EXPECT_NEAR(m.hd95, distances[static_cast<size_t>(std::ceil(0.95 * distances.size())) - 1], 1e-5);
  }
}

// A bright ball of radius 8 mm on a dark background, anisotropic and rotated.
Volume ballPhantom(const ImageGeometry& g, const Vector3& centre, double radius) {
  Volume v{g, std::vector<float>(g.voxelCount())};
  for (int k = 0; k < g.size[2]; ++k)
    for (int j = 0; j < g.size[1]; ++j)
      for (int i = 0; i < g.size[0]; ++i)
        v.voxels[g.offset(i, j, k)] = (g.toPhysical(Vector3(i, j, k)) - centre).norm() < radius ? 100.0f : 20.0f;
  return v;
}

TEST(EdgePotential, ForcesPointToTheBallsSurface) {
  const ImageGeometry g = grid({40, 36, 30}, Vector3(0.8, 0.9, 1.1), Vector3(5, -7, 3), skewDirection());
  const Vector3 centre = g.toPhysical(Vector3(19.5, 17.5, 14.5));
  const double radius = 8.0;
  const DirectionField field(ballPhantom(g, centre, radius), EdgeOptions{});
  // Edges: every edge voxel within a voxel of the sphere.
  long long edgeCount = 0;
  for (int k = 0; k < g.size[2]; ++k)
    for (int j = 0; j < g.size[1]; ++j)
      for (int i = 0; i < g.size[0]; ++i)
        if (field.edges().voxels[g.offset(i, j, k)]) {
          ++edgeCount;
          EXPECT_NEAR((g.toPhysical(Vector3(i, j, k)) - centre).norm(), radius, 1.1);
        }
  EXPECT_GT(edgeCount, 500);
  // Forces 3 mm inside point outward, 3 mm outside point inward (within 30 degrees).
  Matrix3X probes(2 * 26, 3);
  std::vector<Vector3> radial;
  int row = 0;
  for (int x = -1; x <= 1; ++x)
    for (int y = -1; y <= 1; ++y)
      for (int z = -1; z <= 1; ++z) {
        if (!x && !y && !z) continue;
        const Vector3 u = Vector3(x, y, z).normalized();
        probes.row(row++) = (centre + (radius - 3) * u).transpose();
        probes.row(row++) = (centre + (radius + 3) * u).transpose();
        radial.push_back(u);
        radial.push_back(-u);
      }
  const Matrix3X forces = field.sample(probes);
  for (int p = 0; p < probes.rows(); ++p) {
    EXPECT_NEAR(forces.row(p).norm(), 1.0, 0.05) << p;
    EXPECT_GT(forces.row(p).dot(radial[p].transpose()), std::cos(M_PI / 6)) << p;
  }
  // Beyond the capture range, and outside the image, no force.
  Matrix3X far(2, 3);
  far.row(0) = centre.transpose();  // 8 mm from every edge > 6 mm
  far.row(1) = (centre + Vector3(500, 0, 0)).transpose();
  EXPECT_LT(field.sample(far).norm(), 1e-12);
}

// A bright shell (100, radius 4.5 to 9 mm) around a dimmer core (70) on a dark
// background (20): a strong outer edge (step 80) and a weak inner one (step 30).
Volume shellPhantom(const ImageGeometry& g, const Vector3& centre) {
  Volume v{g, std::vector<float>(g.voxelCount())};
  for (int k = 0; k < g.size[2]; ++k)
    for (int j = 0; j < g.size[1]; ++j)
      for (int i = 0; i < g.size[0]; ++i) {
        const double r = (g.toPhysical(Vector3(i, j, k)) - centre).norm();
        v.voxels[g.offset(i, j, k)] = r < 4.5 ? 70.0f : r < 9.0 ? 100.0f : 20.0f;
      }
  return v;
}

// Points on a sphere in the 26 grid-free directions.
Matrix3X pointsOnSphere(const Vector3& centre, double radius) {
  Matrix3X points(26, 3);
  int row = 0;
  for (int x = -1; x <= 1; ++x)
    for (int y = -1; y <= 1; ++y)
      for (int z = -1; z <= 1; ++z)
        if (x || y || z) points.row(row++) = (centre + radius * Vector3(x, y, z).normalized()).transpose();
  return points;
}

// Edge voxels within 1.1 mm of the sphere of `radius` (the edge test above allows the same).
long long edgesNear(const DirectionField& field, const Vector3& centre, double radius) {
  const Mask& edges = field.edges();
  const ImageGeometry& g = edges.geometry;
  long long count = 0;
  for (int k = 0; k < g.size[2]; ++k)
    for (int j = 0; j < g.size[1]; ++j)
      for (int i = 0; i < g.size[0]; ++i)
        if (edges.voxels[g.offset(i, j, k)] && std::abs((g.toPhysical(Vector3(i, j, k)) - centre).norm() - radius) < 1.1)
          ++count;
  return count;
}

TEST(EdgePotential, EdgeDistanceIsTheDistanceToTheBallsSurface) {
  const ImageGeometry g = grid({40, 36, 30}, Vector3(0.8, 0.9, 1.1), Vector3(5, -7, 3), skewDirection());
  const Vector3 centre = g.toPhysical(Vector3(19.5, 17.5, 14.5));
  const double radius = 8.0;
  const DirectionField field(ballPhantom(g, centre, radius), EdgeOptions{});
  // Edge voxels lie within 1.1 mm of the sphere (the test above), so the
  // distance to them is |r - 8| to within that plus the interpolation's
  // error of about half a voxel.
  for (double r : {0.0, 3.0, 6.0, 8.0, 11.0})
    for (const Vector3& u : {Vector3(1, 0, 0), Vector3(0, -1, 1).normalized(), Vector3(1, 1, 1).normalized()})
      EXPECT_NEAR(field.edgeDistance(centre + r * u), std::abs(r - radius), 1.7) << "r " << r;
  EXPECT_EQ(field.edgeDistance(centre + Vector3(100, 0, 0)), std::numeric_limits<double>::infinity());
  EdgeOptions plain;
  plain.method = EdgeMethod::GradientMagnitude;
  EXPECT_EQ(DirectionField(ballPhantom(g, centre, radius), plain).edgeDistance(centre),
            std::numeric_limits<double>::infinity());
}

TEST(EdgePotential, LandmarksSetTheEdgeThresholds) {
  const ImageGeometry g = grid({40, 36, 30}, Vector3(0.8, 0.9, 1.1), Vector3(5, -7, 3), skewDirection());
  const Vector3 centre = g.toPhysical(Vector3(19.5, 17.5, 14.5));
  const Volume image = shellPhantom(g, centre);
  EdgeOptions byImage;
  byImage.reference = EdgeReference::Image;
  const DirectionField imageField(image, byImage);
  EXPECT_EQ(imageField.scale().reference, EdgeReference::Image);
  const long long outer = edgesNear(imageField, centre, 9.0), inner = edgesNear(imageField, centre, 4.5);
  // Against the image's 99th percentile both edges are kept (inner/outer area 1/4).
  EXPECT_GT(outer, 500);
  EXPECT_GT(inner, outer / 8);

  // Points on the outer boundary: its edges stay, the weak inner ones go.
  const DirectionField outerField(image, EdgeOptions{}, pointsOnSphere(centre, 9.0));
  EXPECT_EQ(outerField.scale().reference, EdgeReference::Landmarks);
  // A Gaussian-blurred step of height h peaks at h / (sigma sqrt(2 pi)): 31.9
  // for h = 80 and sigma = 1 mm (measured 31.9); 5 % allows for the sampling
  // of the peak on this anisotropic grid and the sphere's curvature.
  const double peak = 1.0 / std::sqrt(2 * M_PI);
  EXPECT_NEAR(outerField.scale().magnitude, 80 * peak, 0.05 * 80 * peak);
  EXPECT_GT(edgesNear(outerField, centre, 9.0), 0.9 * outer);
  EXPECT_EQ(edgesNear(outerField, centre, 4.5), 0);

  // Points on the weak inner boundary: both edges are kept.
  const DirectionField innerField(image, EdgeOptions{}, pointsOnSphere(centre, 4.5));
  EXPECT_NEAR(innerField.scale().magnitude, 30 * peak, 0.05 * 30 * peak);  // measured 11.85 of 11.97
  EXPECT_GT(edgesNear(innerField, centre, 4.5), 0.9 * inner);
  EXPECT_GT(edgesNear(innerField, centre, 9.0), 0.9 * outer);

  // Points where the image has no edge cannot set the thresholds: off the
  // grid, and in the flat middle of the core (0.5 mm from the centre, 3 mm
  // and more from its boundary: the blurred step has fallen to a few % of
  // its peak there). Both are refused rather than used.
  const Matrix3X offGrid = pointsOnSphere(centre + Vector3(500, 0, 0), 9.0), flat = pointsOnSphere(centre, 0.5);
  const EdgeOptions byLandmarks;
  EXPECT_THROW(DirectionField(image, byLandmarks, offGrid), LandmarksOffEdges);
  EXPECT_THROW(DirectionField(image, byLandmarks, flat), LandmarksOffEdges);
  // With the image as the reference the same points are not used at all.
  const DirectionField flatByImage(image, byImage, flat);
  EXPECT_EQ(flatByImage.scale().reference, EdgeReference::Image);
  EXPECT_EQ(edgesNear(flatByImage, centre, 4.5), inner);
}

TEST(EdgePotential, BadOptionsAreRefused) {
  EdgeOptions options;
  options.sigma = std::nan("");
  EXPECT_THROW(checkEdgeOptions(options), Error);
  options = EdgeOptions{};
  options.ofImage = {0.5, 0.2};
  EXPECT_THROW(checkEdgeOptions(options), Error);
  options = EdgeOptions{};
  options.ofLandmarks = {0.5, std::nan("")};
  EXPECT_THROW(checkEdgeOptions(options), Error);
  options = EdgeOptions{};
  options.landmarkReach = -1;
  EXPECT_THROW(checkEdgeOptions(options), Error);
  options = EdgeOptions{};
  options.captureRange = -1;
  EXPECT_THROW(checkEdgeOptions(options), Error);
}

}  // namespace
}  // namespace dynsub
