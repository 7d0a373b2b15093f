#include <gtest/gtest.h>

#include "dynsub/TextFields.h"

namespace dynsub {
namespace {

// A number is read whole and in decimal: a decimal comma, a second point or
// a hexadecimal value is no number, where std::stod alone reads one.
TEST(TextFields, ParseNumberReadsWholeDecimalNumbers) {
  double value = 0;
  EXPECT_TRUE(parseNumber("-1.5e3", value));
  EXPECT_EQ(value, -1500.0);
  EXPECT_TRUE(parseNumber("nan", value));
  for (const char* field : {"0,5", "1.5.5", "0x1", "0X1p3", "8abc", ""}) EXPECT_FALSE(parseNumber(field, value)) << field;
}

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

// The landmark and point-cloud readers split CSV lines with it.
TEST(TextFields, SplitCsvFieldsKeepsQuotedSeparators) {
  using Fields = std::vector<std::string>;
  EXPECT_EQ(splitCsvFields("1, 2,\"left, anterior\"\r", ','), (Fields{"1", "2", "left, anterior"}));
  EXPECT_EQ(splitCsvFields("1;2;", ';'), (Fields{"1", "2", ""}));
  EXPECT_EQ(splitCsvFields("", ','), (Fields{""}));
}

TEST(TextFields, WrappedBreaksLongLinesAtSpaces) {
  EXPECT_EQ(wrapped("short  |  line", 20), "short  |  line");  // inner spaces kept
  EXPECT_EQ(wrapped("not saved: /a/long/path.mrk.json holds 2 lists", 22),
            "not saved:\n/a/long/path.mrk.json\nholds 2 lists");
  EXPECT_EQ(wrapped("abcdefghij", 4), "abcd\nefgh\nij");  // no space: cut
  EXPECT_EQ(wrapped("one\ntwo three", 5), "one\ntwo\nthree");
  EXPECT_EQ(wrapped("", 5), "");
  EXPECT_EQ(wrapped("abc    def", 5), "abc\ndef");                         // the break's spaces dropped
  EXPECT_EQ(wrapped("/home/jos\xc3\xa9/x", 10), "/home/jos\n\xc3\xa9/x");  // not inside a character
}

// ITK's and VTK's messages name the object that failed by its address.
TEST(TextFields, AfterObjectAddressKeepsTheReason) {
  EXPECT_EQ(afterObjectAddress("vtkXMLDataParser (0x55bb834416e0): Error parsing XML"), "Error parsing XML");
  EXPECT_EQ(afterObjectAddress("itk::ERROR: NrrdImageIO(0x5561): Read: Error reading x.nrrd:"),
            "Read: Error reading x.nrrd:");
  EXPECT_EQ(afterObjectAddress("no object (here): named"), "no object (here): named");
}

}  // namespace
}  // namespace dynsub

