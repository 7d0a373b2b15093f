// The parameter table: names that the command line, Slicer and plans can
// tell apart, defaults inside their own ranges, and values checked as they
// are set.
#include <set>

#include <gtest/gtest.h>

#include "dynsub/Error.h"
#include "dynsub/SegmentParameters.h"

namespace dynsub {
namespace {

TEST(SegmentParameters, NamesAreDistinctAndDerivedOneWay) {
  std::set<std::string> keys, flags, camel, groups;
  for (const ParameterGroup& g : segmentParameterGroups()) groups.insert(g.name);
  for (const Parameter& p : segmentParameters()) {
    EXPECT_TRUE(keys.insert(p.key()).second) << p.key();
    EXPECT_TRUE(flags.insert(p.flag()).second) << p.flag();
    EXPECT_TRUE(camel.insert(p.camelName()).second) << p.camelName();
    EXPECT_EQ(groups.count(p.group), 1u) << p.key() << " is in no group";
    EXPECT_FALSE(p.help.empty()) << p.key();
    EXPECT_EQ(findSegmentParameter(p.key()), &p);
    // A switch on by default needs its opposite for tools that can only switch on.
    if (const auto* on = std::get_if<Parameter::Switch>(&p.value)) {
      SegmentParameters defaults;
      if ((*on)(defaults)) {
        EXPECT_TRUE(p.opposite.has_value()) << p.key();
      }
    }
  }
  const Parameter* capture = findSegmentParameter("capture_range_mm");
  ASSERT_NE(capture, nullptr);
  EXPECT_EQ(capture->flag(), "--capture-range");
  EXPECT_EQ(capture->camelName(), "captureRange");
  EXPECT_EQ(findSegmentParameter("capture_range"), nullptr);  // a length's key carries its unit
  EXPECT_EQ(findSegmentParameter("no_such_parameter"), nullptr);
}

TEST(SegmentParameters, DefaultsLieInTheirRangesAndPassTheChecks) {
  const SegmentParameters defaults;
  for (const Parameter& p : segmentParameters()) {
    const ParameterValue v = parameterValue(defaults, p);
    if (const double* d = std::get_if<double>(&v)) {
      EXPECT_GE(*d, p.low) << p.key();
      EXPECT_LE(*d, p.high) << p.key();
    }
    if (const int* i = std::get_if<int>(&v)) {
      EXPECT_GE(*i, p.low) << p.key();
      EXPECT_LE(*i, p.high) << p.key();
    }
  }
  EXPECT_NO_THROW(checkSegmentParameters(defaults));
}

TEST(SegmentParameters, SettingChecksKindRangeAndChoices) {
  SegmentParameters p;
  const Parameter& sigma = *findSegmentParameter("sigma_mm");
  setParameter(p, sigma, 1.5);
  EXPECT_EQ(p.segment.edges.sigma, 1.5);
  EXPECT_THROW(setParameter(p, sigma, -1.0), Error);
  EXPECT_THROW(setParameter(p, sigma, std::numeric_limits<double>::quiet_NaN()), Error);
  EXPECT_THROW(setParameter(p, sigma, std::string("wide")), Error);

  const Parameter& level = *findSegmentParameter("max_level");
  setParameter(p, level, 2.0);  // a plan's 2.0 is 2
  EXPECT_EQ(p.segment.simulation.maxLevel, 2);
  EXPECT_THROW(setParameter(p, level, 1.5), Error);
  EXPECT_THROW(setParameter(p, level, 7), Error);

  const Parameter& potential = *findSegmentParameter("potential");
  setParameter(p, potential, std::string("gradient"));
  EXPECT_EQ(p.segment.edges.method, EdgeMethod::GradientMagnitude);
  EXPECT_EQ(std::get<std::string>(parameterValue(p, potential)), "gradient");
  EXPECT_THROW(setParameter(p, potential, std::string("canny")), Error);

  const Parameter& ends = *findSegmentParameter("slice_ends");
  setParameter(p, ends, false);
  EXPECT_FALSE(p.segment.sliceEnds.enabled);
  EXPECT_THROW(setParameter(p, ends, 1.0), Error);

  const Parameter& low = *findSegmentParameter("edge_low");
  EXPECT_TRUE(std::holds_alternative<std::monostate>(parameterValue(p, low)));
  setParameter(p, low, 0.5);
  EXPECT_EQ(p.edgeLow, 0.5);
  setParameter(p, low, ParameterValue());
  EXPECT_FALSE(p.edgeLow.has_value());

  try {
    setParameter(p, sigma, 50.0);
    FAIL() << "a sigma of 50 mm was accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("sigma_mm (--sigma) must be in 0.1..20, got 50"), std::string::npos)
        << e.what();
  }
}

TEST(SegmentParameters, EdgeThresholdsGoToTheReferenceInUse) {
  SegmentParameters p;
  p.edgeLow = 0.6;
  p.edgeHigh = 0.9;
  const EdgeOptions defaults;
  const SegmentOptions withPoints = segmentOptions(p, true);
  EXPECT_EQ(withPoints.edges.ofLandmarks.low, 0.6);
  EXPECT_EQ(withPoints.edges.ofLandmarks.high, 0.9);
  EXPECT_EQ(withPoints.edges.ofImage.low, defaults.ofImage.low);
  const SegmentOptions withoutPoints = segmentOptions(p, false);
  EXPECT_EQ(withoutPoints.edges.ofImage.low, 0.6);
  EXPECT_EQ(withoutPoints.edges.ofLandmarks.low, defaults.ofLandmarks.low);
  p.segment.edges.reference = EdgeReference::Image;
  EXPECT_EQ(segmentOptions(p, true).edges.ofImage.high, 0.9);
  // Thresholds that cross are refused as the edge detector would refuse them.
  p.edgeLow = 0.95;
  EXPECT_THROW(segmentOptions(p, true), Error);
}

TEST(SegmentParameters, OneTensionAndOneRigidityForEveryDirection) {
  SegmentParameters p;
  p.segment.simulation.material.tensionU = 0.3;
  p.segment.simulation.material.rigidityUU = 0.05;
  const Material& m = segmentOptions(p, true).simulation.material;
  EXPECT_EQ(m.tensionV, 0.3);
  EXPECT_EQ(m.rigidityVV, 0.05);
  EXPECT_EQ(m.rigidityUV, 0.1);
}

}  // namespace
}  // namespace dynsub
