#include <gtest/gtest.h>

#include <cmath>

#include "dynsub/Error.h"
#include "dynsub/SubjectGenerator.h"

namespace dynsub {
namespace {

// A 56 mm cube at 1 mm: an ellipsoid of intensity 200 (label 1) inside a
// shell of 100 (label 2), air (0) around both.
struct Phantom {
  Volume image, labels;
};

Phantom phantom() {
  Phantom p;
  p.image.geometry.size = {56, 56, 56};
  p.image.geometry.origin = Vector3(-27.5, -27.5, -27.5);
  p.image.voxels.assign(56 * 56 * 56, 0.0f);
  p.labels = p.image;
  for (int k = 0; k < 56; ++k)
    for (int j = 0; j < 56; ++j)
      for (int i = 0; i < 56; ++i) {
        const Vector3 x = p.image.geometry.toPhysical(Vector3(i, j, k));
        const double inner = std::pow(x.x() / 14, 2) + std::pow(x.y() / 10, 2) + std::pow(x.z() / 8, 2);
        const double outer = x.squaredNorm() / (22.0 * 22.0);
        const long long at = p.image.geometry.offset(i, j, k);
        if (inner <= 1) {
          p.image.voxels[at] = 200;
          p.labels.voxels[at] = 1;
        } else if (outer <= 1) {
          p.image.voxels[at] = 100;
          p.labels.voxels[at] = 2;
        }
      }
  return p;
}

// Only the anatomy's map: no contrast change, bias, blur or noise to speak of.
SubjectSettings moveOnly() {
  SubjectSettings s;
  s.gammaSpread = 0;
  s.biasSpread = 0;
  s.blurMm = {0, 0};
  s.snr = {1000, 1000};
  s.sourceSnr = 1000;
  s.warpSpacingMm = 15;
  s.warpMm = 3;
  return s;
}

TEST(SubjectGenerator, TheSameSeedGivesTheSameSubjectAndAnotherSeedAnother) {
  const Phantom p = phantom();
  const SubjectSettings settings;
  const Subject a = makeSubject(p.image, p.labels, settings, 7);
  const Subject b = makeSubject(p.image, p.labels, settings, 7);
  const Subject c = makeSubject(p.image, p.labels, settings, 8);
  EXPECT_EQ(a.image.voxels, b.image.voxels);
  EXPECT_EQ(a.labels.voxels, b.labels.voxels);
  EXPECT_NE(a.labels.voxels, c.labels.voxels);
  EXPECT_NE(a.draw.snr, c.draw.snr);
}

// The labels move with the anatomy: with the acquisition's changes switched
// off, label 1 lies on the bright ellipsoid and label 0 on air. Voxels whose
// trilinear sample straddles a boundary are the only disagreement, so 97 %
// agreement is asked of each (the ellipsoid has about 4700 voxels, a third
// of them on its boundary layer; a misplaced label would fall far below).
TEST(SubjectGenerator, LabelsAgreeWithTheMovedImage) {
  const Phantom p = phantom();
  for (const std::uint64_t seed : {1u, 2u, 3u}) {
    const Subject s = makeSubject(p.image, p.labels, moveOnly(), seed);
    ASSERT_TRUE(s.image.geometry.sameGridAs(s.labels.geometry));
    long long inner = 0, innerBright = 0, air = 0, airDark = 0;
    for (std::size_t v = 0; v < s.labels.voxels.size(); ++v) {
      if (s.labels.voxels[v] == 1) {
        ++inner;
        innerBright += s.image.voxels[v] > 150;
      } else if (s.labels.voxels[v] == 0) {
        ++air;
        airDark += s.image.voxels[v] < 50;
      }
    }
    EXPECT_GT(inner, 3000) << seed;
    EXPECT_GE(static_cast<double>(innerBright) / inner, 0.97) << seed;
    EXPECT_GE(static_cast<double>(airDark) / air, 0.97) << seed;
    // The map moved the anatomy: the labels are not the source's.
    EXPECT_NE(s.labels.voxels, p.labels.voxels) << seed;
  }
}

// The deformation never folds, even with control points moved close to the
// bound (0.39 of their spacing); past the bound the settings are refused.
TEST(SubjectGenerator, TheMapDoesNotFoldAndUnsafeWarpsAreRefused) {
  const Phantom p = phantom();
  SubjectSettings settings = moveOnly();
  settings.warpSpacingMm = 12;
  settings.warpMm = 0.39 * 12;
  for (const std::uint64_t seed : {11u, 12u, 13u, 14u}) {
    const Subject s = makeSubject(p.image, p.labels, settings, seed);
    EXPECT_GT(s.draw.smallestJacobian, 0.0) << seed;
    // The label volumes follow the map's overall volume change rather than
    // vanishing or doubling.
    long long inner = 0, source = 0;
    for (const float l : s.labels.voxels) inner += l == 1;
    for (const float l : p.labels.voxels) source += l == 1;
    EXPECT_GT(inner, 0.6 * source) << seed;
    EXPECT_LT(inner, 1.6 * source) << seed;
  }
  settings.warpMm = 0.41 * 12;
  EXPECT_THROW(makeSubject(p.image, p.labels, settings, 1), Error);
}

// Air carries Rician noise: its magnitude is Rayleigh, of mean sigma
// sqrt(pi / 2), so the drawn sigma is recovered from air far from the head
// within 5 % (about 9000 such voxels).
TEST(SubjectGenerator, NoiseHasTheDrawnSignalToNoiseRatio) {
  const Phantom p = phantom();
  SubjectSettings settings;
  settings.snr = {25, 25};
  const Subject s = makeSubject(p.image, p.labels, settings, 5);
  EXPECT_DOUBLE_EQ(s.draw.snr, 25);
  EXPECT_NEAR(s.draw.noiseSigma, s.draw.whiteMatter * std::sqrt(1.0 / 625 - 1.0 / (70.0 * 70.0)), 1e-9);
  double sum = 0;
  long long count = 0;
  const ImageGeometry& g = s.image.geometry;
  for (int k = 0; k < g.size[2]; ++k)
    for (int j = 0; j < g.size[1]; ++j)
      for (int i = 0; i < g.size[0]; ++i)
        if (g.toPhysical(Vector3(i, j, k)).norm() > 33) {
          sum += s.image.at(i, j, k);
          ++count;
        }
  ASSERT_GT(count, 5000);
  EXPECT_NEAR(sum / count / std::sqrt(M_PI / 2), s.draw.noiseSigma, 0.05 * s.draw.noiseSigma);
}

// A thick-slice subject: 3 mm along one axis, the same physical extent, and
// its labels on the fine grid.
TEST(SubjectGenerator, ThickSlicesKeepTheExtentAndTheFineLabels) {
  const Phantom p = phantom();
  SubjectSettings settings = moveOnly();
  settings.thickFraction = 1;
  const Subject s = makeSubject(p.image, p.labels, settings, 21);
  ASSERT_TRUE(s.draw.thickAxis.has_value());
  const int axis = *s.draw.thickAxis;
  EXPECT_DOUBLE_EQ(s.image.geometry.spacing[axis], 3.0);
  EXPECT_EQ(s.image.geometry.size[axis], 56 / 3);
  EXPECT_TRUE(s.labels.geometry.sameGridAs(p.labels.geometry));
  // The first thick slice's centre is the centre of the three fine ones.
  EXPECT_NEAR(s.image.geometry.origin[axis], p.image.geometry.origin[axis] + 1.0, 1e-12);
}

// thick_axis names the thick axis; the axis is still drawn for, so the
// subject is otherwise the one its seed gives: the same labels and SNR as
// with the axis drawn, and on the drawn axis the same image.
TEST(SubjectGenerator, ANamedThickAxisChangesOnlyTheAxis) {
  const Phantom p = phantom();
  SubjectSettings settings = moveOnly();
  settings.thickFraction = 1;
  const Subject drawn = makeSubject(p.image, p.labels, settings, 21);
  ASSERT_TRUE(drawn.draw.thickAxis.has_value());
  for (const int axis : {0, 1, 2}) {
    SubjectSettings named = settings;
    setSubjectSetting(named, "thick_axis", std::to_string(axis));
    const Subject s = makeSubject(p.image, p.labels, named, 21);
    ASSERT_EQ(s.draw.thickAxis, axis);
    EXPECT_DOUBLE_EQ(s.image.geometry.spacing[axis], 3.0);
    EXPECT_EQ(s.labels.voxels, drawn.labels.voxels);
    EXPECT_EQ(s.draw.snr, drawn.draw.snr);
    if (axis == *drawn.draw.thickAxis) {
      EXPECT_EQ(s.image.voxels, drawn.image.voxels);
    }
  }
  SubjectSettings bad = settings;
  EXPECT_THROW(setSubjectSetting(bad, "thick_axis", "3"), Error);
  EXPECT_THROW(setSubjectSetting(bad, "thick_axis", "1.5"), Error);
}

// Nested shells for synthesized subjects: a ball of label 1 (source
// intensity 100) inside white (200), grey (100) and dark (30) shells with
// no label, air (0) around them.
Phantom shells() {
  Phantom p;
  p.image.geometry.size = {56, 56, 56};
  p.image.geometry.origin = Vector3(-27.5, -27.5, -27.5);
  p.image.voxels.assign(56 * 56 * 56, 0.0f);
  p.labels = p.image;
  for (int k = 0; k < 56; ++k)
    for (int j = 0; j < 56; ++j)
      for (int i = 0; i < 56; ++i) {
        const double r = p.image.geometry.toPhysical(Vector3(i, j, k)).norm();
        const long long at = p.image.geometry.offset(i, j, k);
        p.labels.voxels[at] = r < 8 ? 1 : 0;
        p.image.voxels[at] = r < 8 ? 100 : r < 14 ? 200 : r < 20 ? 100 : r < 24 ? 30 : 0;
      }
  return p;
}

// A synthesized subject's intensities come from its labels and the source's
// tissue classes alone, in a T1-like or a T2-like order. With the blur, the
// bias and the noise switched off, the realistic subject of the same seed
// (same anatomy, the source's intensities) tells which class each voxel
// came from. Tolerances: textures are drawn with sigma at most 0.03 of the
// bright end (200 here), so 0.15 x 200 = 30 is five sigmas; class means are
// drawn at least 0.15 of the bright end apart, and a voxel's class is read
// from a trilinear sample, so voxels on a class's boundary (a third of each
// shell) are left out by asking the realistic sample to be within 5 of the
// class's source value.
TEST(SubjectGenerator, SynthesizedSubjectsDrawTheirIntensitiesFromLabelsAndTissueClasses) {
  const Phantom p = shells();
  SubjectSettings realistic = moveOnly();
  realistic.gammaSpread = 0;
  for (const double t2 : {0.0, 1.0}) {
    SubjectSettings settings = realistic;
    settings.synthesized = true;
    settings.t2Fraction = t2;
    settings.snr = {1e3, 1e3};
    const std::uint64_t seed = t2 > 0 ? 31 : 32;
    const Subject synthesized = makeSubject(p.image, p.labels, settings, seed);
    const Subject source = makeSubject(p.image, p.labels, realistic, seed);
    EXPECT_EQ(synthesized.labels.voxels, source.labels.voxels) << "one seed, one anatomy";
    EXPECT_EQ(synthesized.draw.contrast, t2 > 0 ? "t2" : "t1");
    double sum[5] = {}, count[5] = {};  // label 1, white, grey, dark, air
    double lowest[5], highest[5];
    std::fill(lowest, lowest + 5, 1e9);
    std::fill(highest, highest + 5, -1e9);
    for (std::size_t v = 0; v < source.image.voxels.size(); ++v) {
      const float s = source.image.voxels[v];
      int c = -1;
      if (synthesized.labels.voxels[v] == 1)
        c = 0;
      else if (std::abs(s - 200) < 5)
        c = 1;
      else if (std::abs(s - 100) < 5)
        c = 2;
      else if (std::abs(s - 30) < 5)
        c = 3;
      else if (s == 0)
        c = 4;
      if (c < 0) continue;
      const float value = synthesized.image.voxels[v];
      sum[c] += value;
      ++count[c];
      lowest[c] = std::min<double>(lowest[c], value);
      highest[c] = std::max<double>(highest[c], value);
    }
    double mean[5];
    for (int c = 0; c < 5; ++c) {
      ASSERT_GT(count[c], 200) << c;
      mean[c] = sum[c] / count[c];
      if (c < 4) {
        EXPECT_LT(highest[c] - mean[c], 30) << c;
        EXPECT_LT(mean[c] - lowest[c], 30) << c;
      }
    }
    EXPECT_LT(highest[4], 1.0) << "air stays dark (noise at SNR 1000 only)";
    if (t2 > 0) {
      EXPECT_GT(mean[3], mean[2] + 0.15 * 200 - 1);  // CSF over grey
      EXPECT_GT(mean[2], mean[1] + 0.15 * 200 - 1);  // grey over white
    } else {
      EXPECT_GT(mean[1], mean[2] + 0.17 * 200 - 1);  // white over grey
      EXPECT_GT(mean[2], mean[3] + 0.2 * 200 - 1);   // grey over CSF
    }
    // The labelled ball is a grey structure: within label_spread of grey.
    EXPECT_LT(std::abs(mean[0] - mean[2]), 0.05 * 200 + 2);
    // Its white matter is known, and sets the noise exactly.
    EXPECT_NEAR(synthesized.draw.noiseSigma, synthesized.draw.whiteMatter / 1e3, 1e-9);
  }
  // A label left out of structure_labels takes its tissue class: the ball
  // (source intensity 100) is then drawn exactly as the grey shell is.
  SubjectSettings cortexLike = realistic;
  cortexLike.synthesized = true;
  cortexLike.blurMm = {0, 0};
  Phantom twoLabels = p;  // a second label, in a corner of air
  twoLabels.labels.voxels[twoLabels.labels.geometry.offset(1, 1, 1)] = 2;
  setSubjectSetting(cortexLike, "structure_labels", "2");
  EXPECT_EQ(cortexLike.structureLabels, (std::vector<int>{2}));
  const Subject asTissue = makeSubject(twoLabels.image, twoLabels.labels, cortexLike, 33);
  const Subject source = makeSubject(p.image, p.labels, realistic, 33);
  std::vector<double> ball, grey;
  for (std::size_t v = 0; v < source.image.voxels.size(); ++v) {
    if (std::abs(source.image.voxels[v] - 100) >= 5) continue;
    (asTissue.labels.voxels[v] == 1 ? ball : grey).push_back(asTissue.image.voxels[v]);
  }
  ASSERT_GT(ball.size(), 500u);
  ASSERT_GT(grey.size(), 500u);
  const auto mean = [](const std::vector<double>& values) {
    double sum = 0;
    for (const double value : values) sum += value;
    return sum / values.size();
  };
  // Two samples of one texture (sigma at most 6 here): their means agree
  // to far better than the label spread's 10.
  EXPECT_NEAR(mean(ball), mean(grey), 1.0);

  setSubjectSetting(cortexLike, "structure_labels", "1,4");  // the phantom has no label 4
  EXPECT_THROW(makeSubject(twoLabels.image, twoLabels.labels, cortexLike, 33), Error);
  SubjectSettings bad = realistic;
  EXPECT_THROW(setSubjectSetting(bad, "structure_labels", "1,2.5"), Error);
  EXPECT_THROW(setSubjectSetting(bad, "mode", "synthetic"), Error);
  setSubjectSetting(bad, "mode", "synthesized");
  EXPECT_TRUE(bad.synthesized);
  bad.labelSpread = 0.2;
  EXPECT_THROW(checkSubjectSettings(bad), Error);
}

}  // namespace
}  // namespace dynsub
