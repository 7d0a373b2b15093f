// The ends beyond the clicked slices (SliceEnds.h) on a noisy elongated
// ellipsoid, clicked on coronal slices over the middle 60 % of its length as
// an expert who skips the ends would: the march finds each end within 2 mm,
// and the segmentation that uses it reaches the ends the clicks left out.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <limits>
#include <random>

#include "dynsub/ClickAppearance.h"
#include "dynsub/Error.h"
#include "dynsub/Labelmap.h"
#include "dynsub/Metrics.h"
#include "dynsub/Segmentation.h"
#include "dynsub/SliceEnds.h"

namespace dynsub {
namespace {

// Half-axes 8, 20, 8 mm (long along y, the coronal slice axis of an identity
// grid), intensity 100 inside and 20 outside with partial volume, noise 10.
struct Cigar {
  Vector3 centre{2, -3, 1}, axes{8, 20, 8};
  bool inside(const Vector3& x) const { return (x - centre).cwiseQuotient(axes).squaredNorm() <= 1.0; }
};

// The intensities of a voxel inside and outside the structure at a point
// (before partial volume and noise).
struct Tissue {
  std::function<double(const Vector3&)> inside = [](const Vector3&) { return 100.0; };
  std::function<double(const Vector3&)> outside = [](const Vector3&) { return 20.0; };
  double noise = 10.0;
};

// `sliceMm`: the voxels' size along y (61 mm of it).
Volume cigarImage(const Cigar& shape, Mask* truth, int sliceMm = 1, const Tissue& tissue = Tissue()) {
  Volume image;
  ImageGeometry& g = image.geometry;
  g.size = {41, 60 / sliceMm + 1, 41};
  g.spacing.y() = sliceMm;
  g.origin = shape.centre - Vector3(20, 30, 20);
  image.voxels.resize(g.voxelCount());
  truth->geometry = g;
  truth->voxels.resize(g.voxelCount());
  std::mt19937_64 random(5);
  std::normal_distribution<double> noise(0.0, tissue.noise);
  for (int k = 0; k < g.size[2]; ++k)
    for (int j = 0; j < g.size[1]; ++j)
      for (int i = 0; i < g.size[0]; ++i) {
        int in = 0;
        for (int c = 0; c < 64; ++c) {
          const Vector3 offset((c % 4 + 0.5) / 4 - 0.5, ((c / 4) % 4 + 0.5) / 4 - 0.5, (c / 16 + 0.5) / 4 - 0.5);
          in += shape.inside(g.toPhysical(Vector3(i, j, k) + offset));
        }
        const Vector3 x = g.toPhysical(Vector3(i, j, k));
        const double share = in / 64.0;
        image.voxels[g.offset(i, j, k)] =
            static_cast<float>((1 - share) * tissue.outside(x) + share * tissue.inside(x) + noise(random));
        truth->voxels[g.offset(i, j, k)] = shape.inside(g.toPhysical(Vector3(i, j, k)));
      }
  return image;
}

// `perSlice` points on each of 5 coronal slices (whole voxels) from -12 to +12 mm of the centre.
std::vector<Landmark> clicks(const Cigar& shape, int perSlice) {
  std::vector<Landmark> landmarks;
  for (int s = 0; s < 5; ++s) {
    const double y = -12.0 + 6.0 * s;
    const double scale = std::sqrt(1.0 - (y / shape.axes.y()) * (y / shape.axes.y()));
    for (int q = 0; q < perSlice; ++q) {
      const double angle = 2.0 * M_PI * (q + 0.5 * s) / perSlice;
      landmarks.push_back({"P" + std::to_string(landmarks.size() + 1),
                           shape.centre + Vector3(shape.axes.x() * scale * std::cos(angle), y,
                                                  shape.axes.z() * scale * std::sin(angle))});
    }
  }
  return landmarks;
}

TEST(SliceEnds, FindBothEndsOfAStructureClickedOnSlices) {
  const Cigar shape;
  Mask truth;
  const Volume image = cigarImage(shape, &truth);
  const std::vector<Landmark> landmarks = clicks(shape, 6);
  SliceEndOptions options;
  options.reach = 0.6;  // of the 24 mm clicked span: the march must stop by itself, before its reach
  const SliceEnds ends = findSliceEnds(image, landmarks, initialFromLandmarks(landmarks), options);
  EXPECT_EQ(ends.axis, 1);
  EXPECT_EQ(ends.slices, 5);
  ASSERT_EQ(ends.ends.size(), 2u);
  // The clicks stop 8 mm short of each tip; the march gets to within 2 mm
  // (its disk's median turns when less than half the disk is inside).
  const Vector3 tips[2] = {shape.centre - Vector3(0, 20, 0), shape.centre + Vector3(0, 20, 0)};
  for (int e = 0; e < 2; ++e) {
    EXPECT_LT((ends.ends[e].end - tips[e]).norm(), 2.0) << ends.ends[e].end.transpose();
    EXPECT_FALSE(ends.ends[e].stoppedByReach);
    EXPECT_EQ(ends.ends[e].marchStart, ends.ends[e].start);  // the centroid is the structure's tissue
  }
  // Per end: the tip, and the end slice's 6 clicks drawn in halfway (the taper).
  EXPECT_EQ(ends.springs.size(), 2u * (1 + 6));
}

// No taper toward an end where the clicked cross-sections widen fast: a
// structure still growing at its last clicked slice (a caudate's head) keeps
// its width beyond it. The cigar's last slice of clicks (y = +12 mm, 0.80 of
// the waist's radius) widened by 1.75 is 1.47 times as wide as the slice
// before it (0.95), past kTaperWidening (1.3); widened by 1.25 (1.05 times)
// it keeps its taper.
TEST(SliceEnds, NoTaperWhereTheClicksWidenFast) {
  const Cigar shape;
  Mask truth;
  const Volume image = cigarImage(shape, &truth);
  std::vector<Landmark> landmarks = clicks(shape, 6);
  const Vector3 lastCentre = shape.centre + Vector3(0, 12, 0);
  for (Landmark& l : landmarks)
    if (std::abs(l.position.y() - lastCentre.y()) < 0.1) l.position = lastCentre + 1.75 * (l.position - lastCentre);
  SliceEndOptions options;
  options.reach = 0.6;
  const SliceEnds ends = findSliceEnds(image, landmarks, initialFromLandmarks(landmarks), options);
  ASSERT_EQ(ends.ends.size(), 2u);
  EXPECT_TRUE(ends.ends[0].sprung && ends.ends[1].sprung);
  EXPECT_TRUE(!ends.ends[0].widening && ends.ends[0].tapered);
  EXPECT_TRUE(ends.ends[1].widening && !ends.ends[1].tapered);
  // The first end's tip and 6 taper springs; the last end's tip alone.
  EXPECT_EQ(ends.springs.size(), 1u + 6 + 1);
  options.taper = false;
  EXPECT_EQ(findSliceEnds(image, landmarks, initialFromLandmarks(landmarks), options).springs.size(), 2u);
  // Widening slowly, as toward an ellipsoid's waist: tapered.
  std::vector<Landmark> slow = clicks(shape, 6);
  for (Landmark& l : slow)
    if (std::abs(l.position.y() - lastCentre.y()) < 0.1) l.position = lastCentre + 1.25 * (l.position - lastCentre);
  options.taper = true;
  EXPECT_TRUE(findSliceEnds(image, slow, initialFromLandmarks(slow), options).ends[1].tapered);
}

// A march that ends at its reach found no end: no spring there, unless asked for.
TEST(SliceEnds, NoSpringWhereTheMarchFoundNoEnd) {
  const Cigar shape;
  Mask truth;
  const Volume image = cigarImage(shape, &truth);
  const std::vector<Landmark> landmarks = clicks(shape, 6);
  SliceEndOptions options;
  options.reach = 0.15;  // 3.6 mm, well inside the 8 mm left to each tip
  const SliceEnds ends = findSliceEnds(image, landmarks, initialFromLandmarks(landmarks), options);
  ASSERT_EQ(ends.ends.size(), 2u);
  EXPECT_TRUE(ends.ends[0].stoppedByReach && ends.ends[1].stoppedByReach);
  EXPECT_TRUE(ends.springs.empty());
  options.springAtReach = true;
  EXPECT_EQ(findSliceEnds(image, landmarks, initialFromLandmarks(landmarks), options).springs.size(), 14u);
}

// A cigar whose intensity falls by `slope` per mm along y from 100 at its
// centre (from its centre on only, with `fromCentre`), with tissue of
// `beyond` going on past its +y tip within 8 mm of its axis, noise 4;
// clicked on its 5 middle slices, and marched from them as far as 0.6 of
// the clicked span (14.4 mm, past the tip 8 mm beyond the last clicked
// slice) with the window about the model's median (`endLevel` 0).
struct DriftingCigar {
  Cigar shape;
  Volume image;
  std::vector<Landmark> landmarks = clicks(shape, 6);
  Vector3 tip = shape.centre + Vector3(0, 20, 0);
  SliceEndOptions options;

  DriftingCigar(double slope, bool fromCentre, double beyond) {
    Tissue tissue;
    tissue.inside = [this, slope, fromCentre](const Vector3& x) {
      const double along = x.y() - shape.centre.y();
      return 100.0 - slope * (fromCentre ? std::max(0.0, along) : along);
    };
    tissue.outside = [this, beyond](const Vector3& x) {
      const Vector3 d = x - shape.centre;
      return d.y() > 0 && std::hypot(d.x(), d.z()) < 8 ? beyond : 20.0;
    };
    tissue.noise = 4.0;
    Mask truth;
    image = cigarImage(shape, &truth, 1, tissue);
    options.reach = 0.6;
    options.endLevel = 0;
  }
  SliceEnds ends() const { return findSliceEnds(image, landmarks, initialFromLandmarks(landmarks), options); }
};

// A structure whose intensity drifts along it (the cigar darkens from 120
// at y = -20 mm to 80 at +20 mm, noise 4), with like tissue (109) going on
// past its +y tip within 8 mm of its axis. About the whole structure's
// median (100 +- 15 on the clicked span) the march from the last clicked
// slice (y = +12, about 88) leaves the window within a few mm, where the
// cigar darkens past 85, well short of the tip; about the end's own level
// it follows the cigar to its tip and stops at the brighter tissue beyond.
TEST(SliceEnds, TheWindowFollowsTheEndsOwnLevel) {
  DriftingCigar cigar(1.0, false, 109.0);
  const SliceEnds whole = cigar.ends();
  ASSERT_EQ(whole.ends.size(), 2u);
  EXPECT_GT((whole.ends[1].end - cigar.tip).norm(), 3.0) << whole.ends[1].end.transpose();
  cigar.options.endLevel = 1;
  const SliceEnds own = cigar.ends();
  ASSERT_EQ(own.ends.size(), 2u);
  EXPECT_LT(own.ends[1].low, 80.0);
  EXPECT_LT(own.ends[1].high, 109.0);
  EXPECT_FALSE(own.ends[1].stoppedByReach);
  EXPECT_LT((own.ends[1].end - cigar.tip).norm(), 2.0) << own.ends[1].end.transpose();
  // The other end, past which the tissue is unlike, is found either way.
  EXPECT_FALSE(whole.ends[0].stoppedByReach || own.ends[0].stoppedByReach);
}

// A cigar that darkens gently toward its +y tip (100 to 90 from its middle),
// with tissue of 108 going on past that tip within 8 mm of its axis, noise 4.
// The window about the whole structure's median holds 108: the march from
// the last clicked slice finds no end. The second, about the end's own
// level (about 94), leaves it where the 108 begins.
TEST(SliceEnds, WhereTheMarchSawNoEndItMarchesAgainAboutTheEndsLevel) {
  DriftingCigar cigar(0.5, true, 108.0);
  cigar.options.endLevelAtReach = 0;  // no second march
  const SliceEnds once = cigar.ends();
  ASSERT_EQ(once.ends.size(), 2u);
  EXPECT_TRUE(once.ends[1].stoppedByReach) << once.ends[1].low << " " << once.ends[1].high;
  EXPECT_FALSE(once.ends[1].marchedAgain);
  EXPECT_GT(once.ends[1].high, 108.0);
  cigar.options.endLevelAtReach = 1;
  const SliceEnds again = cigar.ends();
  ASSERT_EQ(again.ends.size(), 2u);
  EXPECT_TRUE(again.ends[1].marchedAgain);
  EXPECT_FALSE(again.ends[1].stoppedByReach) << again.ends[1].low << " " << again.ends[1].high;
  EXPECT_LT(again.ends[1].high, 108.0);
  EXPECT_LT((again.ends[1].end - cigar.tip).norm(), 2.0) << again.ends[1].end.transpose();
  // The -y end, past which the tissue is unlike, was found by the first march.
  EXPECT_FALSE(again.ends[0].marchedAgain || again.ends[0].stoppedByReach);
  EXPECT_EQ(again.ends[0].end, once.ends[0].end);
}

// A cigar with a core of the outside's intensity (20) within 2.5 mm of its
// axis, as a cerebellum's section near the midline wraps around its white
// matter: the end slices' centroids lie in the core, where the march stops
// at once. It is made again from a point toward a click in the cigar's own
// tissue (outside the core), and stops within 2 mm of where the cigar ends
// on that line (20 sqrt(1 - (r / 8)^2) mm from the centre along y, at r mm
// from the axis): the line meets the boundary at a shallow angle, so the
// disk's median falls over a millimetre or two before leaving the window.
TEST(SliceEnds, AMarchFromACentroidOutsideTheTissueStartsTowardAClick) {
  const Cigar shape;
  Tissue tissue;
  tissue.inside = [&shape](const Vector3& x) {
    return std::hypot(x.x() - shape.centre.x(), x.z() - shape.centre.z()) < 2.5 ? 20.0 : 100.0;
  };
  Mask truth;
  const Volume image = cigarImage(shape, &truth, 1, tissue);
  const std::vector<Landmark> landmarks = clicks(shape, 6);
  const SliceEnds ends = findSliceEnds(image, landmarks, initialFromLandmarks(landmarks), SliceEndOptions());
  ASSERT_EQ(ends.ends.size(), 2u);
  for (const SliceEnd& end : ends.ends) {
    const double r = std::hypot(end.marchStart.x() - shape.centre.x(), end.marchStart.z() - shape.centre.z());
    EXPECT_GT(r, 2.5) << end.marchStart.transpose();
    EXPECT_TRUE(end.sprung);
    EXPECT_FALSE(end.stoppedByReach);
    const double tip = shape.centre.y() + end.side * shape.axes.y() * std::sqrt(1.0 - (r / 8.0) * (r / 8.0));
    EXPECT_NEAR(end.end.y(), tip, 2.0) << end.end.transpose();
  }
}

// The cigar segmented from clicks on its 5 middle slices, and its Dice.
struct SegmentedCigar {
  SegmentResult result;
  double dice = 0;
};

SegmentedCigar segmentCigar(const SegmentOptions& options) {
  const Cigar shape;
  Mask truth;
  const Volume image = cigarImage(shape, &truth);
  const std::vector<Landmark> landmarks = clicks(shape, 6);
  SegmentedCigar s;
  s.result = segment(image, landmarks, initialFromLandmarks(landmarks), options);
  s.dice = compareMasks(labelmapOf(s.result.surface, image.geometry), truth).dice;
  return s;
}

TEST(SliceEnds, TheSegmentationReachesTheUnclickedEnds) {
  SegmentOptions options;
  options.sliceEnds.enabled = false;
  const double without = segmentCigar(options).dice;
  options.sliceEnds.enabled = true;
  const SegmentedCigar with = segmentCigar(options);
  std::printf("Dice without the ends' springs and pressure %.3f, with %.3f\n", without, with.dice);
  EXPECT_EQ(with.result.sliceEnds.ends.size(), 2u);
  EXPECT_FALSE(with.result.sliceEnds.springs.empty());
  EXPECT_GE(with.dice, without + 0.03);
  EXPECT_GE(with.dice, 0.93);
}

// The clicks' own surroundings teach the two classes: the cigar (100) inside,
// the background (20) outside, with noise 10 on both.
TEST(ClickAppearance, LearnsTheInsideAndOutsideOfTheClickedBoundary) {
  const Cigar shape;
  Mask truth;
  const Volume image = cigarImage(shape, &truth);
  const std::vector<Landmark> landmarks = clicks(shape, 6);
  const std::optional<ClickAppearance> a = ClickAppearance::learn(image, landmarks, 1);
  ASSERT_TRUE(a.has_value());
  // Two samples on each side of each of the 30 clicks.
  EXPECT_EQ(a->insideSamples(), 60);
  EXPECT_EQ(a->outsideSamples(), 60);
  // 1.5 and 3 mm from an edge blurred over about a voxel, the samples are
  // the classes' own intensities: the densities hardly overlap.
  EXPECT_GT(a->separation(), 0.9);
  EXPECT_GT(a->score(100), 0.9);
  EXPECT_LT(a->score(20), -0.9);
  // Between the classes the score rises from the outside's to the inside's.
  for (double i = 20; i < 100; i += 10) EXPECT_LE(a->score(i), a->score(i + 10)) << i;
  EXPECT_GT(a->largestSlope(), 0.0);
  // One click per slice gives no inward direction, and so no samples.
  std::vector<Landmark> single;
  for (int s = 0; s < 5; ++s) single.push_back(landmarks[6 * s]);
  EXPECT_FALSE(ClickAppearance::learn(image, single, 1).has_value());
  EXPECT_THROW(ClickAppearance::learn(image, landmarks, 3), Error);
}

TEST(ClickAppearance, ThePressureActsOnlyBeyondTheClickedSpan) {
  const Cigar shape;
  Mask truth;
  const Volume image = cigarImage(shape, &truth);
  const std::vector<Landmark> landmarks = clicks(shape, 6);  // slices at y = -12 .. 12 mm from the centre
  const auto pressureAt = [&](bool before, bool after, double reach = std::numeric_limits<double>::infinity()) {
    // Each end's footprint: its slice's centroid (on the axis) and farthest click.
    const auto end = [&](double y, bool on) {
      const double radius = shape.axes.x() * std::sqrt(1.0 - (y / shape.axes.y()) * (y / shape.axes.y()));
      return on ? std::optional<EndPressure::End>({shape.centre + Vector3(0, y, 0), radius, reach}) : std::nullopt;
    };
    const EndPressure pressure(image, *ClickAppearance::learn(image, landmarks, 1), landmarks, 1, 0.2,
                               end(-12, before), end(12, after));
    MatrixX3 points(7, 3);
    points.row(0) = (shape.centre + Vector3(0, 0, 0)).transpose();    // inside, within the span
    points.row(1) = (shape.centre + Vector3(0, 16, 0)).transpose();   // inside, beyond the last slice
    points.row(2) = (shape.centre + Vector3(0, -16, 0)).transpose();  // inside, before the first
    points.row(3) = (shape.centre + Vector3(0, 25, 0)).transpose();   // background, beyond the last slice
    points.row(4) = (shape.centre + Vector3(0, 35, 0)).transpose();   // on the axis, beyond the image's end
    points.row(5) = (shape.centre + Vector3(7, 16, 0)).transpose();   // beyond the last slice's footprint (6.4 mm)
    points.row(6) = (shape.centre + Vector3(0, 14, 0)).transpose();   // inside, 2 mm beyond the last slice
    EXPECT_GT(pressure.slopeBound(), 0.0);
    return pressure.pressuresAt(points);
  };
  const Eigen::VectorXd both = pressureAt(true, true);
  EXPECT_EQ(both(0), 0.0);
  EXPECT_GT(both(1), 0.15);  // 0.2 at full strength
  EXPECT_GT(both(2), 0.15);
  EXPECT_LT(both(3), -0.15);
  EXPECT_EQ(both(4), 0.0);
  EXPECT_EQ(both(5), 0.0);
  const Eigen::VectorXd after = pressureAt(false, true);
  EXPECT_GT(after(1), 0.15);
  EXPECT_EQ(after(2), 0.0);
  // Reaching 3 mm beyond the end slices: the points 2 mm beyond are pushed,
  // those 4 mm beyond are not.
  const Eigen::VectorXd near = pressureAt(true, true, 3.0);
  EXPECT_GT(near(6), 0.15);
  EXPECT_EQ(near(1), 0.0);
  EXPECT_EQ(near(2), 0.0);
  EXPECT_EQ(near(3), 0.0);
}

// On 3 mm slices the region's whole voxels reach past the margin asked for;
// its span in mm (how far the end pressure reaches) does not.
TEST(SegmentationRegion, ItsSpanIsTheMarginAskedForWhateverTheVoxels) {
  const Cigar shape;
  Mask truth;
  const std::vector<Landmark> landmarks = clicks(shape, 6);  // y from -12 to 12 mm of the centre
  for (int sliceMm : {1, 3}) {
    const Volume image = cigarImage(shape, &truth, sliceMm);
    SegmentOptions options;
    options.margin = 7.0;
    const SegmentationRegion region(image, landmarks, initialFromLandmarks(landmarks), options);
    const auto [low, high] = region.spanAlong(1);
    // The initial model lies within the clicks' span along y, so that span
    // grown by the margin.
    EXPECT_NEAR(low, shape.centre.y() - 12 - 7, 1e-9) << sliceMm;
    EXPECT_NEAR(high, shape.centre.y() + 12 + 7, 1e-9) << sliceMm;
    const ImageGeometry& grid = region.image().geometry;
    EXPECT_LE(grid.origin.y(), low) << sliceMm;
    EXPECT_GE(grid.origin.y() + (grid.size[1] - 1) * grid.spacing.y(), high) << sliceMm;
    if (sliceMm == 3) {
      EXPECT_LT(grid.origin.y(), low - 1.0);  // a third of a voxel and more
    }
  }
}

// From clicks over the middle 60 % only, the pressure carries the surface to
// the cigar's tips, past where the springs' taper leaves it.
TEST(SliceEnds, ThePressureCarriesTheSurfaceToTheEnds) {
  SegmentOptions options;
  options.sliceEnds.pressure = 0;
  const SegmentedCigar springsOnly = segmentCigar(options);
  options.sliceEnds.pressure = 0.2;
  const SegmentedCigar with = segmentCigar(options);
  std::printf("Dice with the ends' springs only %.3f, with the pressure too %.3f\n", springsOnly.dice, with.dice);
  EXPECT_EQ(springsOnly.result.sliceEnds.pressure, 0.0);
  EXPECT_EQ(with.result.sliceEnds.pressure, 0.2);
  EXPECT_EQ(with.result.sliceEnds.insideSamples, 60);
  // The cigar's ends taper: the pressure acts as far as each march went.
  for (const SliceEnd& end : with.result.sliceEnds.ends) {
    EXPECT_TRUE(end.tapered && end.pressed);
    EXPECT_EQ(end.pressureReach, end.length);
  }
  // Measured 0.975 -> 0.980: the tips the taper drew in are filled; half of
  // that gain is asked for.
  EXPECT_GE(with.dice, springsOnly.dice + 0.003);
  EXPECT_GE(with.dice, 0.95);
}

// Clicks that also reach one tip (a slice 1 mm short of it): the pressure
// acts beyond the other end only.
TEST(SliceEnds, NoPressureBeyondAnEndTheClicksReach) {
  const Cigar shape;
  Mask truth;
  const Volume image = cigarImage(shape, &truth);
  std::vector<Landmark> landmarks = clicks(shape, 6);
  const double y = 19, radius = shape.axes.x() * std::sqrt(1.0 - (y / shape.axes.y()) * (y / shape.axes.y()));
  for (int q = 0; q < 6; ++q) {
    const double angle = 2.0 * M_PI * q / 6;
    landmarks.push_back({"T" + std::to_string(q), shape.centre + Vector3(radius * std::cos(angle), y,
                                                                          radius * std::sin(angle))});
  }
  const SegmentResult result = segment(image, landmarks, initialFromLandmarks(landmarks), SegmentOptions());
  ASSERT_EQ(result.sliceEnds.ends.size(), 2u);
  for (const SliceEnd& end : result.sliceEnds.ends) {
    if (end.side < 0) {
      EXPECT_GT(end.length, 2.0);
      EXPECT_TRUE(end.pressed);
    } else {
      EXPECT_LE(end.length, 2.0);
      EXPECT_FALSE(end.pressed);
    }
  }
  EXPECT_EQ(result.sliceEnds.pressure, 0.2);
}

TEST(SliceEnds, NoSpringsForLandmarksOffSlicesOrTooFew) {
  const Cigar shape;
  Mask truth;
  const Volume image = cigarImage(shape, &truth);
  SliceEndOptions options;
  // Points spread over the surface, on no common slice.
  std::vector<Landmark> scattered;
  std::mt19937_64 random(3);
  std::normal_distribution<double> gaussian;
  for (int i = 0; i < 30; ++i) {
    const Vector3 d = Vector3(gaussian(random), gaussian(random), gaussian(random)).normalized();
    scattered.push_back({"S", shape.centre + d.cwiseProduct(shape.axes)});
  }
  const SliceEnds off = findSliceEnds(image, scattered, initialFromLandmarks(scattered), options);
  EXPECT_EQ(off.axis, -1);
  EXPECT_TRUE(off.springs.empty());
  const std::vector<Landmark> few(scattered.begin(), scattered.begin() + 3);
  EXPECT_TRUE(findSliceEnds(image, few, initialFromLandmarks(scattered), options).springs.empty());
}

// Clicks on coronal slices of an image with 4 mm voxels from left to right,
// 12 per slice with a hand's 0.4 mm scatter: the cigar is 16 mm wide there,
// four voxels, so its 60 clicks' left-right positions lie a fraction of a
// voxel apart and chain into fewer "slices" than the five coronal ones. The
// slices are still the coronal ones, where the clicks lie exactly.
TEST(SliceEnds, ThickVoxelsAcrossTheSlicesDoNotMakeSlices) {
  const Cigar shape;
  Mask truth;
  Volume image = cigarImage(shape, &truth);
  ImageGeometry& g = image.geometry;
  g.spacing = Vector3(4, 1, 1);
  g.size[0] = 11;
  image.voxels.resize(static_cast<std::size_t>(g.voxelCount()));
  std::vector<Landmark> landmarks = clicks(shape, 12);
  std::mt19937_64 random(7);
  std::normal_distribution<double> scatter(0.0, 0.4);
  for (Landmark& l : landmarks) l.position += Vector3(scatter(random), 0, scatter(random));
  const SliceEnds ends = findSliceEnds(image, landmarks, initialFromLandmarks(landmarks), SliceEndOptions());
  EXPECT_EQ(ends.axis, 1);
  EXPECT_EQ(ends.slices, 5);
}

TEST(SliceEnds, RefusesImpossibleOptions) {
  for (auto bad :
       {+[](SliceEndOptions& o) { o.window = 0; }, +[](SliceEndOptions& o) { o.reach = -1; },
        +[](SliceEndOptions& o) { o.disk = std::nan(""); }, +[](SliceEndOptions& o) { o.stiffness = 0; },
        +[](SliceEndOptions& o) { o.gap = -0.5; }, +[](SliceEndOptions& o) { o.pressure = -0.1; },
        +[](SliceEndOptions& o) { o.pressure = std::nan(""); }, +[](SliceEndOptions& o) { o.endLevel = 1.5; },
        +[](SliceEndOptions& o) { o.endLevel = -0.1; }, +[](SliceEndOptions& o) { o.endLevelAtReach = 1.5; },
        +[](SliceEndOptions& o) { o.endLevelAtReach = std::nan(""); }}) {
    SliceEndOptions options;
    bad(options);
    EXPECT_THROW(checkSliceEndOptions(options), Error);
  }
}

}  // namespace
}  // namespace dynsub
