#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "TestGrids.h"
#include "dynsub/EdgePotential.h"
#include "dynsub/Error.h"

namespace dynsub {
namespace {

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
  const EdgeField field(ballPhantom(g, centre, radius), EdgeOptions{});
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
  MatrixX3 probes(2 * 26, 3);
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
  const MatrixX3 forces = field.sample(probes);
  for (int p = 0; p < probes.rows(); ++p) {
    EXPECT_NEAR(forces.row(p).norm(), 1.0, 0.05) << p;
    EXPECT_GT(forces.row(p).dot(radial[p].transpose()), std::cos(M_PI / 6)) << p;
  }
  // Beyond the capture range, and outside the image, no force.
  MatrixX3 far(2, 3);
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
MatrixX3 pointsOnSphere(const Vector3& centre, double radius) {
  MatrixX3 points(26, 3);
  int row = 0;
  for (int x = -1; x <= 1; ++x)
    for (int y = -1; y <= 1; ++y)
      for (int z = -1; z <= 1; ++z)
        if (x || y || z) points.row(row++) = (centre + radius * Vector3(x, y, z).normalized()).transpose();
  return points;
}

// Edge voxels within 1.1 mm of the sphere of `radius` (the edge test above allows the same).
long long edgesNear(const EdgeField& field, const Vector3& centre, double radius) {
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
  const EdgeField field(ballPhantom(g, centre, radius), EdgeOptions{});
  // Edge voxels lie within 1.1 mm of the sphere (the test above), so the
  // distance to them is |r - 8| to within that plus the interpolation's
  // error of about half a voxel.
  for (double r : {0.0, 3.0, 6.0, 8.0, 11.0})
    for (const Vector3& u : {Vector3(1, 0, 0), Vector3(0, -1, 1).normalized(), Vector3(1, 1, 1).normalized()})
      EXPECT_NEAR(field.edgeDistance(centre + r * u), std::abs(r - radius), 1.7) << "r " << r;
  EXPECT_EQ(field.edgeDistance(centre + Vector3(100, 0, 0)), std::numeric_limits<double>::infinity());
  EdgeOptions plain;
  plain.method = EdgeMethod::GradientMagnitude;
  EXPECT_EQ(EdgeField(ballPhantom(g, centre, radius), plain).edgeDistance(centre),
            std::numeric_limits<double>::infinity());
}

TEST(EdgePotential, LandmarksSetTheEdgeThresholds) {
  const ImageGeometry g = grid({40, 36, 30}, Vector3(0.8, 0.9, 1.1), Vector3(5, -7, 3), skewDirection());
  const Vector3 centre = g.toPhysical(Vector3(19.5, 17.5, 14.5));
  const Volume image = shellPhantom(g, centre);
  EdgeOptions byImage;
  byImage.reference = EdgeReference::Image;
  const EdgeField imageField(image, byImage);
  EXPECT_EQ(imageField.scale().reference, EdgeReference::Image);
  const long long outer = edgesNear(imageField, centre, 9.0), inner = edgesNear(imageField, centre, 4.5);
  // Against the image's 99th percentile both edges are kept (inner/outer area 1/4).
  EXPECT_GT(outer, 500);
  EXPECT_GT(inner, outer / 8);

  // Points on the outer boundary: its edges stay, the weak inner ones go.
  const EdgeField outerField(image, EdgeOptions{}, pointsOnSphere(centre, 9.0));
  EXPECT_EQ(outerField.scale().reference, EdgeReference::Landmarks);
  // A Gaussian-blurred step of height h peaks at h / (sigma sqrt(2 pi)): 31.9
  // for h = 80 and sigma = 1 mm (measured 31.9); 5 % allows for the sampling
  // of the peak on this anisotropic grid and the sphere's curvature.
  const double peak = 1.0 / std::sqrt(2 * M_PI);
  EXPECT_NEAR(outerField.scale().magnitude, 80 * peak, 0.05 * 80 * peak);
  EXPECT_GT(edgesNear(outerField, centre, 9.0), 0.9 * outer);
  EXPECT_EQ(edgesNear(outerField, centre, 4.5), 0);

  // Points on the weak inner boundary: both edges are kept.
  const EdgeField innerField(image, EdgeOptions{}, pointsOnSphere(centre, 4.5));
  EXPECT_NEAR(innerField.scale().magnitude, 30 * peak, 0.05 * 30 * peak);  // measured 11.85 of 11.97
  EXPECT_GT(edgesNear(innerField, centre, 4.5), 0.9 * inner);
  EXPECT_GT(edgesNear(innerField, centre, 9.0), 0.9 * outer);

  // Points where the image has no edge cannot set the thresholds: off the
  // grid, and in the flat middle of the core (0.5 mm from the centre, 3 mm
  // and more from its boundary: the blurred step has fallen to a few % of
  // its peak there). Both are refused rather than used.
  const MatrixX3 offGrid = pointsOnSphere(centre + Vector3(500, 0, 0), 9.0), flat = pointsOnSphere(centre, 0.5);
  const EdgeOptions byLandmarks;
  EXPECT_THROW(EdgeField(image, byLandmarks, offGrid), LandmarksOffEdges);
  EXPECT_THROW(EdgeField(image, byLandmarks, flat), LandmarksOffEdges);
  // With the image as the reference the same points are not used at all.
  const EdgeField flatByImage(image, byImage, flat);
  EXPECT_EQ(flatByImage.scale().reference, EdgeReference::Image);
  EXPECT_EQ(edgesNear(flatByImage, centre, 4.5), inner);
}

// On 3 mm slices, clicks midway between two slices are 1.5 mm from every
// voxel centre, beyond the landmarks' 1 mm reach: the reach along the thick
// axis is half a slice, so they still set the thresholds from the slices on
// either side (the outer boundary's edge, as on the fine grid).
TEST(EdgePotential, ClicksBetweenThickSlicesSetTheEdgeThresholds) {
  const ImageGeometry g = grid({40, 36, 12}, Vector3(1, 1, 3), Vector3(0, 0, 0), Matrix3::Identity());
  const Vector3 centre = g.toPhysical(Vector3(19.5, 17.5, 6));  // on slice 6
  const Volume image = shellPhantom(g, centre);
  MatrixX3 between(24, 3);
  for (int p = 0; p < 24; ++p) {
    const double angle = 2 * M_PI * p / 12, z = p < 12 ? 1.5 : -1.5, r = std::sqrt(81 - z * z);
    between.row(p) = (centre + Vector3(r * std::cos(angle), r * std::sin(angle), z)).transpose();
  }
  const EdgeField field(image, EdgeOptions{}, between);
  EXPECT_EQ(field.scale().reference, EdgeReference::Landmarks);
  // Thick slices blur the step along z: the peak is lower than the fine
  // grid's 80 / sqrt(2 pi), but far above the 1 % refusal line.
  EXPECT_GT(field.scale().magnitude, 0.3 * 80 / std::sqrt(2 * M_PI));
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
