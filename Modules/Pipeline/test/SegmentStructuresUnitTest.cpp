// Two structures segmented together (SegmentStructures.h) on a phantom where
// alone they must overlap: two spheres of one intensity that merge into one
// blob, with no edge where they meet, each clicked only away from the other.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "dynsub/Error.h"
#include "dynsub/SegmentStructures.h"

namespace dynsub {
namespace {

constexpr double kRadius = 9.0;
const Vector3 kCentreA(-6, 0, 0), kCentreB(6, 0, 0);

bool inSphere(const Vector3& x, const Vector3& centre) { return (x - centre).norm() <= kRadius; }

// A 1 mm grid whose voxel centres lie at half-integers, so that no centre is
// on the plane x = 0 between the structures.
ImageGeometry phantomGrid() {
  ImageGeometry g;
  g.size = {48, 32, 32};
  g.origin = Vector3(-23.5, -15.5, -15.5);
  return g;
}

// Intensity 100 in the union of the spheres and 20 outside, averaged over
// 4^3 sub-samples per voxel (partial volume), with Gaussian noise of 5 (the
// region pressure's window is made of the inside's spread, none without).
Volume phantomImage() {
  std::mt19937_64 random(5);
  std::normal_distribution<double> noise(0.0, 5.0);
  Volume image;
  image.geometry = phantomGrid();
  image.voxels.resize(image.geometry.voxelCount());
  for (int k = 0; k < 32; ++k)
    for (int j = 0; j < 32; ++j)
      for (int i = 0; i < 48; ++i) {
        int in = 0;
        for (int c = 0; c < 64; ++c) {
          const Vector3 offset((c % 4 + 0.5) / 4 - 0.5, ((c / 4) % 4 + 0.5) / 4 - 0.5, (c / 16 + 0.5) / 4 - 0.5);
          const Vector3 x = image.geometry.toPhysical(Vector3(i, j, k) + offset);
          in += inSphere(x, kCentreA) || inSphere(x, kCentreB);
        }
        image.voxels[image.geometry.offset(i, j, k)] = static_cast<float>(20.0 + 80.0 * in / 64.0 + noise(random));
      }
  return image;
}

// Structure A: its sphere's voxels on its side of x = 0 (B's, mirrored).
Mask truth(bool a) {
  Mask m;
  m.geometry = phantomGrid();
  m.voxels.resize(m.geometry.voxelCount());
  for (int k = 0; k < 32; ++k)
    for (int j = 0; j < 32; ++j)
      for (int i = 0; i < 48; ++i) {
        const Vector3 x = m.geometry.toPhysical(Vector3(i, j, k));
        m.voxels[m.geometry.offset(i, j, k)] =
            a ? inSphere(x, kCentreA) && x.x() < 0 : inSphere(x, kCentreB) && x.x() > 0;
      }
  return m;
}

// Points spread over the sphere (a Fibonacci lattice of 60, not on slices),
// those on the structure's own side at least 3 mm from x = 0: the user clicks
// each structure where it is clearly itself.
std::vector<Landmark> clicks(const Vector3& centre) {
  std::vector<Landmark> points;
  const double golden = M_PI * (3 - std::sqrt(5.0));
  for (int n = 0; n < 60; ++n) {
    const double z = 1 - 2 * (n + 0.5) / 60, r = std::sqrt(1 - z * z);
    const Vector3 x = centre + kRadius * Vector3(z, r * std::cos(golden * n), r * std::sin(golden * n));
    if (x.x() * centre.x() > 0 && std::abs(x.x()) >= 3) points.push_back({"P-" + std::to_string(points.size() + 1), x});
  }
  return points;
}

struct PhantomRun {
  Volume image = phantomImage();
  Mask truthA = truth(true), truthB = truth(false);
  std::vector<StructureInputs> structures;
  PhantomRun() {
    for (const bool a : {true, false}) {
      StructureInputs s;
      s.name = a ? "a" : "b";
      s.inputs.landmarks = clicks(a ? kCentreA : kCentreB);
      s.inputs.landmarkSource = s.name + ".mrk.json";
      const Mask* reference = a ? &truthA : &truthB;
      s.inputs.reference = [reference]() -> const Mask& { return *reference; };
      structures.push_back(s);
    }
  }
};

// The region pressure grows each surface through tissue like its inside,
// which here is the other sphere too: alone, each structure swells into the
// other, as a structure does into a neighbour of like intensity.
SegmentParameters phantomParameters() {
  SegmentParameters p;
  p.checkConvention = false;  // a symmetric phantom's mirror fits as well as the clicks
  p.segment.regionPressure = 0.05;
  return p;
}

long long countShared(const Mask& a, const Mask& b) {
  long long n = 0;
  for (std::size_t v = 0; v < a.voxels.size(); ++v) n += a.voxels[v] && b.voxels[v];
  return n;
}

TEST(SegmentStructures, NeighboursWithNoEdgeBetweenThemMeetWithoutOverlapAndLoseOnlyARim) {
  PhantomRun run;
  const StructuresOutcome out = segmentStructures(run.image, run.structures, phantomParameters());
  ASSERT_EQ(out.structures.size(), 2u);
  // The premise: alone, each swells past x = 0 into the other (measured: 104
  // voxels, most of the 141-voxel disc where they meet; 80 would still be a
  // lens worth splitting).
  EXPECT_GE(out.sharedAlone, 80);
  EXPECT_TRUE(out.segmentedAgain[0] && out.segmentedAgain[1]);
  // The barrier: the surfaces themselves now share at most a quarter of
  // what they shared alone (the rest of the joined labelmap's work is done
  // by the join, which leaves no voxel with two labels).
  EXPECT_LE(out.sharedTogether, out.sharedAlone / 4);
  EXPECT_EQ(out.sharedTogether, countShared(out.structures[0].labelmap, out.structures[1].labelmap));
  for (const float label : out.labels.voxels) EXPECT_TRUE(label == 0 || label == 1 || label == 2);
  // Each structure's share of the joined labelmap is as close to its truth
  // as its segmentation alone, within 0.005 (about 14 of its 2880 voxels):
  // the smooth surface, pushed back to the plane where it meets the other,
  // rounds the sharp rim of that plane (measured: 0.948 -> 0.944 and
  // 0.946 -> 0.943; the surfaces then share no voxel).
  for (std::size_t s = 0; s < 2; ++s) {
    SCOPED_TRACE(s);
    EXPECT_GE(out.jointMetrics[s].dice, out.aloneMetrics[s].dice - 0.005);
    EXPECT_GE(out.jointMetrics[s].dice, 0.93);
  }
  EXPECT_GT(out.report.text().find("\"shared_voxels_alone\""), 0u);
}

TEST(SegmentStructures, JoinGivesASharedVoxelToTheClaimantWithTheNearestPoint) {
  ImageGeometry g;
  g.size = {4, 1, 1};
  Mask a{g, {1, 1, 1, 0}}, b{g, {0, 1, 1, 1}};
  MatrixX3 nearA(1, 3), nearB(1, 3);
  nearA << 0, 0, 0;
  nearB << 3, 0, 0;
  const Volume labels = jointLabels({a, b}, {nearA, nearB});
  EXPECT_EQ(labels.voxels, (std::vector<float>{1, 1, 2, 2}));
  // Equally near: the earlier mask.
  MatrixX3 middle(1, 3);
  middle << 1.5, 0, 0;
  EXPECT_EQ(jointLabels({a, b}, {middle, middle}).voxels, (std::vector<float>{1, 1, 1, 2}));
  Mask other;
  other.geometry = g;
  other.geometry.size = {2, 2, 1};
  other.voxels = {1, 0, 0, 1};
  EXPECT_THROW(jointLabels({a, other}, {nearA, nearB}), Error);
}

TEST(SegmentStructures, RefusesOneStructureAndBadOrRepeatedNames) {
  PhantomRun run;
  const SegmentParameters p = phantomParameters();
  EXPECT_THROW(checkStructures({run.structures[0]}, p), Error);
  std::vector<StructureInputs> same = run.structures;
  same[1].name = same[0].name;
  EXPECT_THROW(checkStructures(same, p), Error);
  for (const std::string bad : {"", "..", "a/b", "a b"}) {
    std::vector<StructureInputs> named = run.structures;
    named[0].name = bad;
    EXPECT_THROW(checkStructures(named, p), Error) << bad;
  }
  // A structure's own problem is named with it.
  std::vector<StructureInputs> few = run.structures;
  few[1].inputs.landmarks.resize(3);
  try {
    checkStructures(few, p);
    FAIL() << "three landmarks accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("structure b"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace dynsub
