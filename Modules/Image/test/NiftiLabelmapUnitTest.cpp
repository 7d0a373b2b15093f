// DynSub writes NIfTI labelmaps itself (NiftiLabelmap.h); these tests hold
// them to ITK's own writer, which wrote them before: on axis-aligned,
// oblique, anisotropic and left-handed grids, the file read back by ITK's
// reader has the same voxels and, to float precision, the same geometry, and
// the header says what ITK's says field by field.
#include <gtest/gtest.h>

#include <zlib.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "BridgeGeometry.h"
#include "ItkBridge.h"
#include "ScratchFiles.h"
#include "dynsub/Error.h"
#include "dynsub/ImageIO.h"

namespace dynsub {
namespace {

namespace fs = std::filesystem;

fs::path scratch(const std::string& name) { return scratchFile("NiftiLabelmap", name); }

// A file's bytes, inflated when it is gzipped.
std::string inflated(const fs::path& path) {
  gzFile file = gzopen(path.c_str(), "rb");
  std::string bytes;
  char buffer[1 << 16];
  int got = 0;
  while ((got = gzread(file, buffer, sizeof buffer)) > 0) bytes.append(buffer, static_cast<std::size_t>(got));
  gzclose(file);
  return bytes;
}

template <typename T>
T field(const std::string& bytes, std::size_t at) {
  T value;
  std::memcpy(&value, bytes.data() + at, sizeof value);
  return value;
}

// The rotation a NIfTI-1 header's quatern_b, _c, _d stand for (a >= 0 implied).
Eigen::Matrix3d quaternionRotation(const std::string& header) {
  const double b = field<float>(header, 256), c = field<float>(header, 260), d = field<float>(header, 264);
  const double a = std::sqrt(std::max(0.0, 1 - b * b - c * c - d * d));
  return Eigen::Quaterniond(a, b, c, d).toRotationMatrix();
}

// A mask on `g` with a few voxels of a ball set (and the first voxel, so the
// corners are checked too).
Mask ballOn(const ImageGeometry& g) {
  Mask mask{g, std::vector<std::uint8_t>(static_cast<std::size_t>(g.voxelCount()), 0)};
  const Eigen::Vector3d centre(g.size[0] / 2.0, g.size[1] / 2.0, g.size[2] / 2.0);
  for (int k = 0; k < g.size[2]; ++k)
    for (int j = 0; j < g.size[1]; ++j)
      for (int i = 0; i < g.size[0]; ++i)
        if ((Eigen::Vector3d(i, j, k) - centre).norm() < 0.35 * g.size[0]) mask.voxels[g.offset(i, j, k)] = 1;
  mask.voxels[0] = 1;
  return mask;
}

ImageGeometry grid(const Eigen::Matrix3d& direction, const Eigen::Vector3d& spacing, const Eigen::Vector3d& origin) {
  ImageGeometry g;
  g.size = {23, 19, 17};
  g.spacing = spacing;
  g.origin = origin;
  g.direction = direction;
  return g;
}

Eigen::Matrix3d rotation(double degrees, const Eigen::Vector3d& axis) {
  return Eigen::AngleAxisd(degrees * M_PI / 180, axis.normalized()).toRotationMatrix();
}

// The cases: each branch of the quaternion's computation, both handednesses.
std::vector<std::pair<std::string, ImageGeometry>> grids() {
  Eigen::Matrix3d flippedK = rotation(25, {1, 2, 0.5});
  flippedK.col(2) *= -1;
  return {
      {"Colin27's axes", grid(Eigen::Vector3d(-1, -1, 1).asDiagonal(), {1, 1, 1}, {90, 126, -72})},
      {"identity", grid(Eigen::Matrix3d::Identity(), {0.5, 0.5, 0.5}, {-3, 4.25, 10})},
      {"oblique, anisotropic", grid(rotation(20, {0.3, -1, 0.4}), {0.75, 0.8, 1.5}, {12.5, -30.25, 7})},
      {"half a turn about x", grid(rotation(180, {1, 0, 0}), {1, 1.2, 0.9}, {0, 0, 0})},
      {"near half a turn about y", grid(rotation(170, {0.05, 1, 0}), {1, 1, 2}, {-5, 5, -5})},
      {"near half a turn about z", grid(rotation(175, {0, 0.1, 1}), {0.9, 0.9, 3}, {1, 2, 3})},
      {"left-handed, oblique", grid(flippedK, {1.1, 0.7, 1.3}, {-40, 22, 5.5})},
  };
}

TEST(NiftiLabelmap, ItksReaderSeesWhatItsWriterWrote) {
  for (const auto& [name, g] : grids()) {
    SCOPED_TRACE(name);
    const Mask mask = ballOn(g);
    for (const std::string extension : {".nii.gz", ".nii"}) {
      SCOPED_TRACE(extension);
      const fs::path ours = scratch("ours" + extension), theirs = scratch("itk" + extension);
      writeMask(mask, ours.string(), 7);
      std::vector<std::uint8_t> labels(mask.voxels.size());
      for (std::size_t v = 0; v < labels.size(); ++v) labels[v] = mask.voxels[v] ? 7 : 0;
      itkbridge::writeLabels(toBridge(g), labels, theirs.string());

      itkbridge::Geometry readOurs, readTheirs;
      std::vector<float> voxelsOurs, voxelsTheirs;
      itkbridge::readImage(ours.string(), readOurs, voxelsOurs);
      itkbridge::readImage(theirs.string(), readTheirs, voxelsTheirs);
      EXPECT_EQ(voxelsOurs, voxelsTheirs);
      EXPECT_EQ(readOurs.size, readTheirs.size);
      // Both headers hold floats: the geometry read back agrees to a float's
      // precision (a few 1e-7 of the largest value, 126 mm here).
      for (int a = 0; a < 3; ++a) {
        EXPECT_NEAR(readOurs.spacing[a], readTheirs.spacing[a], 1e-6);
        EXPECT_NEAR(readOurs.origin[a], readTheirs.origin[a], 1e-4);
        EXPECT_NEAR(readOurs.origin[a], g.origin[a], 1e-4);
      }
      for (int e = 0; e < 9; ++e) {
        EXPECT_NEAR(readOurs.direction[e], readTheirs.direction[e], 1e-6);
        EXPECT_NEAR(readOurs.direction[e], g.direction(e / 3, e % 3), 1e-6);
      }

      // The header, field by field: everything ITK writes, the same; the
      // quaternion, offsets and affine rows equal to a float's precision.
      const std::string a = inflated(ours), b = inflated(theirs);
      ASSERT_EQ(a.size(), b.size());
      EXPECT_EQ(a.substr(352), b.substr(352)) << "the voxels";
      const std::size_t floats[] = {76, 80, 84, 88, 92, 96, 100, 104, 108, 112, 116};
      for (std::size_t at : floats) EXPECT_EQ(field<float>(a, at), field<float>(b, at)) << "offset " << at;
      // The quaternions as the rotations they stand for (q and -q are one
      // rotation, and a half turn may be written either way).
      EXPECT_LT((quaternionRotation(a) - quaternionRotation(b)).cwiseAbs().maxCoeff(), 2e-6);
      for (std::size_t at = 268; at < 328; at += 4)
        EXPECT_NEAR(field<float>(a, at), field<float>(b, at), 2e-6 * (1 + std::abs(field<float>(b, at))))
            << "offset " << at;
      auto bytesOutside = [](const std::string& s) { return s.substr(0, 76) + s.substr(120, 256 - 120) + s.substr(328, 24); };
      EXPECT_EQ(bytesOutside(a), bytesOutside(b)) << "the header's other fields";
    }
  }
}

TEST(NiftiLabelmap, AGridTooLargeForNiftiOneIsRefusedAndNothingIsWritten) {
  ImageGeometry g;
  g.size = {40000, 1, 1};
  const Mask mask{g, std::vector<std::uint8_t>(40000, 1)};
  const fs::path path = scratch("too_large.nii.gz");
  fs::remove(path);
  try {
    writeMask(mask, path.string());
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("does not fit a NIfTI-1 header"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find(path.string()), std::string::npos) << e.what();
  }
  EXPECT_FALSE(fs::exists(path));
}

}  // namespace
}  // namespace dynsub
