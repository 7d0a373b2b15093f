// The convergence record (ConvergenceHistory.h): restarted levels, the levels'
// end measures, and its CSV.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include "dynsub/ConvergenceHistory.h"
#include "dynsub/Error.h"

namespace dynsub {
namespace {

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

TEST(ConvergenceHistory, ALevelsEndErrorGoesOnItsLastStep) {
  ConvergenceHistory h;
  h.add({0, 1, 10.0, 1.5});
  h.add({0, 2, 9.0});
  h.add({1, 1, 4.0, 0.9});
  h.add({1, 2, 3.0});
  h.setLevelEndError(0, 0.75);
  h.setLevelEndError(1, 0.5);
  h.setLevelEndError(2, 0.25);  // no such level: nothing changes
  ASSERT_EQ(h.samples.size(), 4u);
  EXPECT_DOUBLE_EQ(h.samples[0].fitError, 1.5);
  EXPECT_DOUBLE_EQ(h.samples[1].fitError, 0.75);
  EXPECT_DOUBLE_EQ(h.samples[2].fitError, 0.9);
  EXPECT_DOUBLE_EQ(h.samples[3].fitError, 0.5);
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
  // A header without steps is named as such (the plot would have nothing to draw).
  std::ofstream(path) << "# fit_error: rms landmark distance (mm)\nlevel,step,energy,fit_error\n";
  try {
    readConvergenceCsv(path);
    FAIL() << "a history without steps was accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find(path + ": a convergence history with no steps"), std::string::npos)
        << e.what();
  }
  std::filesystem::remove(path);
  EXPECT_THROW(readConvergenceCsv(path), Error);
}

}  // namespace
}  // namespace dynsub
