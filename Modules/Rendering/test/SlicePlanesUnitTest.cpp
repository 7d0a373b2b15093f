// The slice planes of an image (SlicePlanes.h), which need no display.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include "dynsub/Error.h"
#include "dynsub/SlicePlanes.h"

namespace dynsub {
namespace {

Volume makeVolume(const Matrix3& direction) {
  Volume v;
  v.geometry.size = {10, 12, 14};
  v.geometry.spacing = Vector3(0.5, 1.0, 2.0);
  v.geometry.origin = Vector3(3, -4, 5);
  v.geometry.direction = direction;
  v.voxels.assign(v.geometry.voxelCount(), 0.0f);
  for (std::size_t i = 0; i < v.voxels.size(); ++i) v.voxels[i] = static_cast<float>(i % 200);
  return v;
}

TEST(SlicePlanes, ColinsAxesGiveTheAnatomicalSlices) {
  // NIfTI RAS stored as ITK LPS: i to the right, j anterior, k superior.
  const ImageSlices slices(makeVolume(Vector3(-1, -1, 1).asDiagonal()));
  EXPECT_EQ(slices.axis(SliceOrientation::Sagittal), 0);
  EXPECT_EQ(slices.axis(SliceOrientation::Coronal), 1);
  EXPECT_EQ(slices.axis(SliceOrientation::Axial), 2);
  const SlicePlane axial = slices.plane(SliceOrientation::Axial, 3);
  EXPECT_NEAR(axial.origin.z(), 5 + 3 * 2.0, 1e-12);
  EXPECT_NEAR(axial.thickness, 2.0, 1e-12);
  // Radiological: the patient's left on the right, anterior up, seen from below.
  EXPECT_NEAR(axial.right.x(), 1.0, 1e-12);
  EXPECT_NEAR(axial.up.y(), -1.0, 1e-12);
  EXPECT_NEAR(axial.normal.z(), -1.0, 1e-12);
  EXPECT_EQ(slices.sliceThrough(SliceOrientation::Axial, axial.origin + Vector3(7, 7, 0.9)), 3);
  EXPECT_EQ(slices.sliceThrough(SliceOrientation::Axial, Vector3(0, 0, 1e6)), 13);  // clamped
}

TEST(SlicePlanes, ObliqueAxesGiveOrthonormalScreenAxesInTheSlice) {
  const Matrix3 rotation =
      (Eigen::AngleAxisd(0.4, Vector3(1, 2, 3).normalized()) * Eigen::AngleAxisd(0.2, Vector3::UnitY()))
          .toRotationMatrix();
  const ImageSlices slices(makeVolume(rotation));
  for (SliceOrientation o : {SliceOrientation::Axial, SliceOrientation::Coronal, SliceOrientation::Sagittal}) {
    const SlicePlane p = slices.plane(o, 2);
    const int a = slices.axis(o);
    EXPECT_NEAR(std::abs(p.normal.dot(rotation.col(a))), 1.0, 1e-12);
    EXPECT_NEAR(p.right.dot(p.up), 0.0, 1e-12);
    EXPECT_NEAR(p.right.cross(p.up).dot(p.normal), 1.0, 1e-12);
    // Every voxel centre of slice 2 lies on the plane.
    Vector3 index = Vector3::Zero();
    index[a] = 2;
    index[(a + 1) % 3] = 5;
    index[(a + 2) % 3] = 7;
    EXPECT_NEAR(p.distance(slices.geometry().toPhysical(index)), 0.0, 1e-9);
  }
  // Each orientation takes a different image axis.
  EXPECT_NE(slices.axis(SliceOrientation::Axial), slices.axis(SliceOrientation::Coronal));
  EXPECT_NE(slices.axis(SliceOrientation::Axial), slices.axis(SliceOrientation::Sagittal));
  EXPECT_NE(slices.axis(SliceOrientation::Coronal), slices.axis(SliceOrientation::Sagittal));
}

TEST(SlicePlanes, GreyWindowSpansThePercentiles) {
  const ImageSlices slices(makeVolume(Matrix3::Identity()));
  // Intensities 0..199 uniformly: 1st to 99.5th percentile is about 2 to 199.
  EXPECT_NEAR(slices.level() - 0.5 * slices.window(), 2.0, 2.0);
  EXPECT_NEAR(slices.level() + 0.5 * slices.window(), 199.0, 2.0);
  Volume empty;
  EXPECT_THROW(ImageSlices{empty}, Error);
}

// A bright, wide background around a dim structure: the whole image's
// window is the background's, the neighbourhood's the structure's.
TEST(SlicePlanes, GreyWindowAroundABoxIsItsNeighbourhoods) {
  Volume volume;
  volume.geometry.size = {60, 60, 60};
  volume.geometry.spacing = Vector3(1, 1, 1);
  volume.voxels.assign(60 * 60 * 60, 1000.0f);
  for (int k = 20; k < 40; ++k)
    for (int j = 20; j < 40; ++j)
      for (int i = 20; i < 40; ++i) volume.voxels[volume.geometry.offset(i, j, k)] = 10.0f + (i + j + k) % 50;
  const ImageSlices slices(volume);
  // The whole image's: from the structure's dim values (its 4 % of the
  // voxels hold the 1st percentile) to the background's 1000.
  EXPECT_GT(slices.window(), 900.0);
  // The box 22..37 mm and 2 mm around it: only the structure's 10..59,
  // widened by a tenth of their span (4.9) on each side.
  MatrixX3 box(2, 3);
  box << 22, 22, 22, 37, 37, 37;
  const ImageSlices::GreyWindow around = slices.windowAround(box, 2.0);
  EXPECT_NEAR(around.level - 0.5 * around.window, 10.0 - 4.9, 1.0);
  EXPECT_NEAR(around.level + 0.5 * around.window, 59.0 + 4.9, 1.0);
  // A box outside the image, clamped to its corner: too few voxels, the whole image's window.
  box << -50, -50, -50, -40, -40, -40;
  const ImageSlices::GreyWindow outside = slices.windowAround(box, 1.0);
  EXPECT_DOUBLE_EQ(outside.window, slices.window());
  EXPECT_DOUBLE_EQ(outside.level, slices.level());
}

}  // namespace
}  // namespace dynsub
