// Reading an evaluation plan (Evaluation.h): its whole numbers. The plan's
// other errors are checked through the command (TestEvaluation.sh).
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

#include "dynsub/Error.h"
#include "dynsub/Evaluation.h"

namespace dynsub {
namespace {

// A plan of one structure, protocol and split, with `protocol` and `seeds`
// as JSON text. Its files are not opened by readEvaluationPlan.
EvaluationPlan readPlan(const std::string& protocol, const std::string& seeds) {
  // One file per process and test: CTest runs the tests side by side.
  const std::string path =
      (std::filesystem::temp_directory_path() /
       ("dynsub_plan_" + std::to_string(::getpid()) + "_" +
        ::testing::UnitTest::GetInstance()->current_test_info()->name() + ".json"))
          .string();
  std::ofstream(path) << R"({"reference": "aal.nii.gz", "images": [{"name": "colin", "path": "ch2.nii.gz"}],
    "structures": [{"name": "caudate_left", "labels": [71], "orientation": "coronal"}],
    "protocols": [)" << protocol
                      << R"(], "splits": [{"name": "test", "seeds": )" << seeds << "}]}";
  try {
    EvaluationPlan plan = readEvaluationPlan(path);
    std::remove(path.c_str());
    return plan;
  } catch (...) {
    std::remove(path.c_str());
    throw;
  }
}

std::string errorOf(const std::string& protocol, const std::string& seeds) {
  try {
    readPlan(protocol, seeds);
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

TEST(EvaluationPlan, WholeNumbersWrittenWithAPointAreTaken) {
  const EvaluationPlan plan = readPlan(R"({"name": "six", "slices": 6.0, "points_per_slice": 5})", "[4294967295]");
  EXPECT_EQ(plan.protocols.at(0).clicks.slices, 6);
  EXPECT_EQ(plan.protocols.at(0).clicks.pointsPerSlice, 5);
  EXPECT_EQ(plan.splits.at(0).seeds.at(0), 4294967295u);
}

TEST(EvaluationPlan, FractionsAndNumbersOutOfRangeAreRefused) {
  EXPECT_NE(errorOf(R"({"name": "six", "slices": 1.5})", "[1]").find("slices must be a whole number, got 1.5"),
            std::string::npos);
  EXPECT_NE(errorOf(R"({"name": "six", "mistakes": "2"})", "[1]").find("mistakes must be a whole number"),
            std::string::npos);
  EXPECT_NE(errorOf(R"({"name": "six"})", "[4294967296]").find("a seed must be in 0..4294967295, got 4294967296"),
            std::string::npos);
  EXPECT_NE(errorOf(R"({"name": "six"})", "[-1]").find("a seed must be in 0..4294967295, got -1"),
            std::string::npos);
  EXPECT_NE(errorOf(R"({"name": "six", "points_per_slice": 1e12})", "[1]").find("points_per_slice must be in"),
            std::string::npos);
}

}  // namespace
}  // namespace dynsub
