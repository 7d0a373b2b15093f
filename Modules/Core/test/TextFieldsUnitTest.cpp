#include <gtest/gtest.h>

#include "dynsub/TextFields.h"

namespace dynsub {
namespace {

TEST(TextFields, EditDistanceIgnoresCase) {
  EXPECT_EQ(editDistance("segmnet", "segment"), 2u);  // two substitutions (a swap)
  EXPECT_EQ(editDistance("Caudate_L", "caudate_l"), 0u);
  EXPECT_EQ(editDistance("", "fit"), 3u);
  EXPECT_EQ(editDistance("--landmark", "--landmarks"), 1u);
}

TEST(TextFields, NearestWordNamesOnlyASlip) {
  const std::vector<std::string> commands{"limit", "mesh", "fit", "deform", "segment", "evaluate"};
  EXPECT_EQ(nearestWord("segmnet", commands), "segment");
  EXPECT_EQ(nearestWord("evalute", commands), "evaluate");
  // A third of the letters, and at least one, may differ: "fix" is near
  // "fit", "frobnicate" is near nothing.
  EXPECT_EQ(nearestWord("fix", commands), "fit");
  EXPECT_EQ(nearestWord("frobnicate", commands), "");
  EXPECT_EQ(nearestWord("xyz", commands), "");
}

// The label lists' parsers rest on it: an empty item is kept, so that "71,"
// is refused rather than read as 71.
TEST(TextFields, SplitItemsKeepsEmptyItemsAsWritten) {
  using Items = std::vector<std::string>;
  EXPECT_EQ(splitItems("71, 72", ','), (Items{"71", " 72"}));
  EXPECT_EQ(splitItems("71,", ','), (Items{"71", ""}));
  EXPECT_EQ(splitItems("71,,72", ','), (Items{"71", "", "72"}));
  EXPECT_EQ(splitItems("", ';'), (Items{""}));
  EXPECT_EQ(trimmed(" Caudate_L \t"), "Caudate_L");
  EXPECT_EQ(trimmed(" \t "), "");
}

}  // namespace
}  // namespace dynsub

