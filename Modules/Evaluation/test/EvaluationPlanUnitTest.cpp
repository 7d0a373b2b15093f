// Reading an evaluation plan (Evaluation.h): its whole numbers and its
// cohorts. The plan's other errors are checked through the command
// (TestEvaluation.sh).
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

// A value of the wrong JSON type, or a key missing, is named where it is
// (nlohmann's own text would be "[json.exception.type_error.302] type must
// be string, but is number").
TEST(EvaluationPlan, WrongTypesAndMissingKeysAreNamedWhereTheyAre) {
  EXPECT_NE(errorOf(R"({"name": 6})", "[1]").find("a protocol's name must be a string, got 6"), std::string::npos);
  EXPECT_NE(errorOf(R"({"slices": 6})", "[1]").find("a protocol has no 'name'"), std::string::npos);
  EXPECT_NE(errorOf(R"({"name": "six", "scatter_mm": "1"})", "[1]")
                .find("protocol 'six': scatter_mm must be a number, got \"1\""),
            std::string::npos);
  EXPECT_NE(
      errorOf(R"({"name": "six", "seed_only": 1})", "[1]").find("protocol 'six': seed_only must be true or false"),
      std::string::npos);
  EXPECT_NE(errorOf(R"({"name": "six", "coverage": 0.5})", "[1]").find("protocol 'six': coverage must be a list"),
            std::string::npos);
  EXPECT_NE(errorOf(R"({"name": "six"})", "7").find("split 'test': seeds must be a list, got 7"), std::string::npos);
  for (const std::string& e : {errorOf(R"({"name": 6})", "[1]"), errorOf(R"({"name": "six"})", "7")})
    EXPECT_EQ(e.find("json.exception"), std::string::npos) << e;
}

// nlohmann would keep the last of a repeated key and stop reading after the
// plan's object; either may hide what was meant.
TEST(EvaluationPlan, RepeatedKeysAndTrailingTextAreRefused) {
  EXPECT_NE(errorOf(R"({"name": "six", "slices": 6, "slices": 3})", "[1]")
                .find("the key 'slices' is given twice in one object"),
            std::string::npos);
  EXPECT_NE(errorOf(R"({"name": "six"})", "[1]}]} {").find("not valid JSON"), std::string::npos);
}

// On a plan's images every split runs: a seed two splits share for one
// structure would score the same clicks as tuning and as test. An empty
// list of a split's structures is a slip, not "all".
TEST(EvaluationPlan, SplitsSharingClicksOrListingNoStructureAreRefused) {
  EXPECT_NE(errorOf(R"({"name": "six"})", R"([1, 2]}, {"name": "tuning", "seeds": [2])")
                .find("splits 'test' and 'tuning' share seed 2 for structure 'caudate_left'"),
            std::string::npos);
  EXPECT_EQ(errorOf(R"({"name": "six"})", R"([1, 2]}, {"name": "tuning", "seeds": [3])"), "");
  EXPECT_NE(errorOf(R"({"name": "six"})", R"([1], "structures": [])").find("split 'test' lists no structures"),
            std::string::npos);
}

TEST(EvaluationPlan, ScatterAndMistakeDistancesHaveARange) {
  EXPECT_NE(errorOf(R"({"name": "six", "scatter_mm": 1e6})", "[1]").find("scatter must be in 0..100 mm"),
            std::string::npos);
  EXPECT_NE(errorOf(R"({"name": "six", "mistakes": 1, "mistake_distance_mm": -1})", "[1]")
                .find("the mistake distance must be in 0..100 mm"),
            std::string::npos);
  EXPECT_EQ(errorOf(R"({"name": "six", "scatter_mm": 100})", "[1]"), "");
}

// A plan of cohorts only, with `cohort` as JSON text (tuning and test splits).
std::string cohortError(const std::string& cohort, EvaluationPlan* plan = nullptr) {
  const std::string path = (std::filesystem::temp_directory_path() /
                            ("dynsub_cohort_" + std::to_string(::getpid()) + "_" +
                             ::testing::UnitTest::GetInstance()->current_test_info()->name() + ".json"))
                               .string();
  std::ofstream(path) << R"({"cohorts": [)" << cohort << R"(],
    "structures": [{"name": "caudate_left", "labels": [71], "orientation": "coronal"}],
    "protocols": [{"name": "six"}], "splits": [{"name": "tuning", "seeds": [1]}, {"name": "test", "seeds": [101]}]})";
  std::string error;
  try {
    const EvaluationPlan read = readEvaluationPlan(path);
    if (plan) *plan = read;
  } catch (const Error& e) {
    error = e.what();
  }
  std::remove(path.c_str());
  return error;
}

TEST(EvaluationPlan, CohortsTakeSettingsAndSubjectsPerSplit) {
  EvaluationPlan plan;
  ASSERT_EQ(cohortError(R"({"name": "noisy", "image": "ch2.nii.gz", "labels": "aal.nii.gz",
      "settings": {"snr": [15, 20], "thick_fraction": 0.5, "mode": "synthesized"},
      "subjects": {"tuning": [1, 2], "test": [101]}})",
                        &plan),
            "");
  const EvaluationCohort& cohort = plan.cohorts.at(0);
  EXPECT_TRUE(cohort.settings.synthesized);
  EXPECT_EQ(cohort.settings.snr[0], 15);
  EXPECT_EQ(cohort.settings.snr[1], 20);
  EXPECT_EQ(cohort.settings.thickFraction, 0.5);
  ASSERT_EQ(cohort.subjects.size(), 2u);
  for (const auto& [split, seeds] : cohort.subjects)
    EXPECT_EQ(seeds, (split == "tuning" ? std::vector<std::uint64_t>{1, 2} : std::vector<std::uint64_t>{101})) << split;
}

TEST(EvaluationPlan, CohortsWithSharedSubjectsUnknownSplitsOrBadSettingsAreRefused) {
  const std::string start = R"({"name": "noisy", "image": "ch2.nii.gz", "labels": "aal.nii.gz", )";
  EXPECT_NE(cohortError(start + R"("subjects": {"tuning": [1, 2], "test": [2]}})")
                .find("subject 2 is listed twice (in splits 't"),
            std::string::npos);
  // Across cohorts: a seed draws the same anatomy from the same image or
  // labels (by whatever path), so it stays in one split; another image's
  // and labels' subject 2 is another.
  const std::string thick = R"(, {"name": "thick", "image": "./ch2.nii.gz", "labels": "aal.nii.gz",
      "settings": {"thick_fraction": 1}, )";
  const std::string tuning = start + R"("subjects": {"tuning": [1, 2]}})";
  EXPECT_NE(cohortError(tuning + thick + R"("subjects": {"test": [2]}})")
                .find("cohort 'thick': subject 2 is in split 'test', and cohort 'noisy' draws it from the same image "
                      "in split 'tuning'"),
            std::string::npos);
  EXPECT_EQ(cohortError(tuning + thick + R"("subjects": {"tuning": [2]}})"), "");
  EXPECT_NE(cohortError(tuning + R"(, {"name": "other", "image": "t2.nii.gz", "labels": "x/../aal.nii.gz",
      "subjects": {"test": [2]}})")
                .find("draws it from the same labels in split 'tuning'"),
            std::string::npos);
  EXPECT_EQ(cohortError(tuning + R"(, {"name": "other", "image": "t2.nii.gz", "labels": "hammers.nii.gz",
      "subjects": {"test": [2]}})"),
            "");
  EXPECT_NE(cohortError(start + R"("subjects": {"training": [1]}})").find("unknown split 'training'"),
            std::string::npos);
  EXPECT_NE(cohortError(start + R"("subjects": {"tuning": [1], "test": []}})").find("split 'test' has no subjects"),
            std::string::npos);
  EXPECT_NE(cohortError(start + R"("settings": {"noise": 2}, "subjects": {"test": [1]}})").find("unknown setting"),
            std::string::npos);
  EXPECT_NE(cohortError(start + R"("settings": {"warp_mm": 40}, "subjects": {"test": [1]}})").find("fold"),
            std::string::npos);
}

// The plans the documentation reruns are read as they are bundled (their
// images are not opened here). The thick-slice plan's cohorts are one
// subject set at 1 mm and in 3 mm slices along each index axis, with a
// held-out split of other subjects.
TEST(EvaluationPlan, TheBundledPlansAreRead) {
  for (const auto& entry : std::filesystem::directory_iterator(DYNSUB_DATA_DIR "/Evaluation")) {
    if (entry.path().extension() != ".json") continue;
    EXPECT_NO_THROW(readEvaluationPlan(entry.path().string())) << entry.path();
  }
  const EvaluationPlan thick = readEvaluationPlan(DYNSUB_DATA_DIR "/Evaluation/thick_orientation_plan.json");
  ASSERT_EQ(thick.cohorts.size(), 4u);
  ASSERT_EQ(thick.splits.size(), 2u);
  const std::vector<std::pair<std::string, std::vector<std::uint64_t>>> subjects{
      {"held_out", {704, 705, 706}}, {"thick_orientation", {701, 702, 703}}};  // in the order of their names
  EXPECT_EQ(thick.cohorts[0].subjects, subjects);
  EXPECT_EQ(thick.cohorts[0].settings.thickMm, 1);  // slices of one voxel: 1 mm, with the others' draws
  for (int axis = 0; axis < 3; ++axis) {
    const SubjectSettings& settings = thick.cohorts[static_cast<std::size_t>(axis) + 1].settings;
    EXPECT_EQ(settings.thickFraction, 1);
    EXPECT_EQ(settings.thickAxis, axis);
    EXPECT_EQ(thick.cohorts[static_cast<std::size_t>(axis) + 1].subjects, thick.cohorts[0].subjects);
  }
}

}  // namespace
}  // namespace dynsub
