// Visualization pieces that need no display: slice planes and the convergence
// history's bookkeeping and file format.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include "dynsub/ConvergenceHistory.h"
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

TEST(ConvergenceHistory, ARestartedLevelDropsItsEarlierSteps) {
  ConvergenceHistory h;
  for (int s = 1; s <= 5; ++s) h.add({0, s, 10.0 - s});
  for (int s = 1; s <= 3; ++s) h.add({1, s, 4.0 - s});
  h.add({1, 1, 3.5});  // level 1 restarted with a smaller time step
  h.add({1, 2, 3.0});
  ASSERT_EQ(h.samples.size(), 7u);
  EXPECT_EQ(h.samples[4].step, 5);
  EXPECT_EQ(h.samples[5].level, 1);
  EXPECT_EQ(h.samples[5].step, 1);
  EXPECT_DOUBLE_EQ(h.samples[5].energy, 3.5);
}

TEST(ConvergenceHistory, CsvRoundTripKeepsUnmeasuredErrors) {
  ConvergenceHistory h;
  h.fitErrorName = "rms landmark distance (mm)";
  h.add({0, 1, 1234.5, 2.25});
  h.add({0, 2, 1000.125});
  h.add({1, 1, 99.0, 0.5});
  const std::string path = (std::filesystem::temp_directory_path() / "dynsub_convergence_test.csv").string();
  writeConvergenceCsv(h, path);
  const ConvergenceHistory back = readConvergenceCsv(path);
  EXPECT_EQ(back.fitErrorName, h.fitErrorName);
  ASSERT_EQ(back.samples.size(), 3u);
  EXPECT_DOUBLE_EQ(back.samples[0].fitError, 2.25);
  EXPECT_TRUE(std::isnan(back.samples[1].fitError));
  EXPECT_DOUBLE_EQ(back.samples[1].energy, 1000.125);
  EXPECT_EQ(back.samples[2].level, 1);

  std::ofstream(path) << "level,step,energy,fit_error\n0,1,5,\n0,x,4,\n";
  try {
    readConvergenceCsv(path);
    FAIL() << "a malformed line was accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("line 3"), std::string::npos) << e.what();
  }
  std::ofstream(path) << "a,b\n";
  EXPECT_THROW(readConvergenceCsv(path), Error);
  std::filesystem::remove(path);
  EXPECT_THROW(readConvergenceCsv(path), Error);
}

}  // namespace
}  // namespace dynsub
