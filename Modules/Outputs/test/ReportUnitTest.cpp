#include "dynsub/Report.h"

#include <gtest/gtest.h>

#include "dynsub/Error.h"

namespace {

// The exact text matters: report.json is read by scripts, workflows and the
// tests of other commands, and its numbers must keep their kind (an integer
// count is not written as 3.0).
TEST(Report, WritesValuesInTheOrderSetWithTheirKinds) {
  dynsub::Report child;
  child.set("dice", 0.85);
  child.set("leaked", false);
  dynsub::Report r;
  r.set("image", std::string("ch2.nii.gz"));
  r.set("levels", 1);
  r.set("points", static_cast<long>(-3));
  r.set("landmarks", static_cast<std::size_t>(36));
  r.set("position_lps_mm", dynsub::Vector3(1.5, -2, 0.25));
  r.set("first_voxel", std::array<int, 3>{1, 2, 3});
  r.set("warnings", std::vector<std::string>{});
  r.set("metrics", child);
  r.set("residuals", std::vector<dynsub::Report>{});
  r.set("ends", std::vector<dynsub::Report>{child});
  r.set("springs", std::vector<dynsub::Vector3>{dynsub::Vector3(1, 2, 3)});
  r.set("levels", 2);  // replaced in place: the order does not change
  EXPECT_EQ(r.text(),
            "{\n"
            "  \"image\": \"ch2.nii.gz\",\n"
            "  \"levels\": 2,\n"
            "  \"points\": -3,\n"
            "  \"landmarks\": 36,\n"
            "  \"position_lps_mm\": [\n    1.5,\n    -2.0,\n    0.25\n  ],\n"
            "  \"first_voxel\": [\n    1,\n    2,\n    3\n  ],\n"
            "  \"warnings\": [],\n"
            "  \"metrics\": {\n    \"dice\": 0.85,\n    \"leaked\": false\n  },\n"
            "  \"residuals\": [],\n"
            "  \"ends\": [\n    {\n      \"dice\": 0.85,\n      \"leaked\": false\n    }\n  ],\n"
            "  \"springs\": [\n    [\n      1.0,\n      2.0,\n      3.0\n    ]\n  ]\n"
            "}\n");
}

TEST(Report, MergeAddsAndReplacesInOrder) {
  dynsub::Report a, b;
  a.set("x", 1);
  a.set("y", 2);
  b.set("y", 3);
  b.set("z", 4);
  a.merge(b);
  EXPECT_EQ(a.text(), "{\n  \"x\": 1,\n  \"y\": 3,\n  \"z\": 4\n}\n");
  EXPECT_EQ(a.text(-1), "{\"x\":1,\"y\":3,\"z\":4}\n");
}

TEST(Report, AnEmptyReportIsAnEmptyObject) { EXPECT_EQ(dynsub::Report().text(), "{}\n"); }

TEST(Report, AFileThatCannotBeWrittenIsAnErrorNamingIt) {
  try {
    dynsub::Report().write("/nonexistent-directory/report.json");
    FAIL() << "expected dynsub::Error";
  } catch (const dynsub::Error& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent-directory/report.json"), std::string::npos) << e.what();
  }
}

}  // namespace
