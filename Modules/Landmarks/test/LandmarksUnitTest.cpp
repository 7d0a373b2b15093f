#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

#include "ScratchFiles.h"
#include "dynsub/Error.h"
#include "dynsub/Landmarks.h"

namespace dynsub {
namespace {

namespace fs = std::filesystem;

fs::path scratch(const std::string& name) { return scratchFile("Landmarks", name); }

std::vector<Landmark> sample() {
  return {{"head", Vector3(-12.5, 30.25, 7.125)}, {"tail", Vector3(1e-3, -2.0, 1234.5678)}, {"", Vector3(0, 0, 0)}};
}

TEST(Landmarks, RoundTripThroughEveryFormatAndCoordinateSystem) {
  for (const std::string name : {"points.mrk.json", "points.fcsv", "points.csv"})
    for (CoordinateSystem system : {CoordinateSystem::LPS, CoordinateSystem::RAS}) {
      const fs::path path = scratch(name);
      writeLandmarks(sample(), path.string(), system);
      const auto read = readLandmarks(path.string());
      ASSERT_EQ(read.size(), 3u) << name;
      for (std::size_t i = 0; i < 3; ++i) {
        EXPECT_LT((read[i].position - sample()[i].position).norm(), 1e-9) << name;
      }
      EXPECT_EQ(read[0].label, "head") << name;
      EXPECT_EQ(read[2].label, "F-3") << name;  // unnamed points get Slicer's default names
    }
}

TEST(Landmarks, RasFilesAreTurnedIntoLps) {
  const fs::path json = scratch("ras.mrk.json");
  std::ofstream(json.string()) << R"({"@schema": "x", "markups": [{"type": "Fiducial", "coordinateSystem": "RAS",
    "coordinateUnits": "mm", "controlPoints": [
      {"id": "1", "label": "a", "position": [10.0, 20.0, 30.0], "positionStatus": "defined"},
      {"id": "2", "label": "b", "position": [1.0, 2.0, 3.0], "positionStatus": "undefined"}]}]})";
  auto read = readLandmarks(json.string());
  ASSERT_EQ(read.size(), 1u);  // the undefined point is skipped
  EXPECT_EQ(read[0].position, Vector3(-10, -20, 30));

  const fs::path fcsv = scratch("old.fcsv");
  std::ofstream(fcsv.string()) << "# Markups fiducial file version = 4.6\n# CoordinateSystem = 0\n"
                                  "# columns = id,x,y,z,ow,ox,oy,oz,vis,sel,lock,label,desc,associatedNodeID\n"
                                  "vtkMRMLMarkupsFiducialNode_0,5,6,7,0,0,0,1,1,1,0,F-1,,\n";
  read = readLandmarks(fcsv.string());
  ASSERT_EQ(read.size(), 1u);
  EXPECT_EQ(read[0].position, Vector3(-5, -6, 7));
  EXPECT_EQ(read[0].label, "F-1");
}

// A markups file with a point list per structure: each list on its own,
// with its name and its own coordinate system; a list without points is
// left out. readLandmarks still gives every point of the file, and a .csv
// is one list without a name.
TEST(Landmarks, AMarkupsFileGivesEachPointListOnItsOwn) {
  const fs::path json = scratch("two.mrk.json");
  std::ofstream(json.string()) << R"({"markups": [
    {"name": "Caudate L", "coordinateSystem": "LPS", "controlPoints": [
      {"label": "c1", "position": [1.0, 2.0, 3.0]}, {"label": "c2", "position": [4.0, 5.0, 6.0]}]},
    {"coordinateSystem": "RAS", "controlPoints": [{"label": "p1", "position": [10.0, 20.0, 30.0]}]}]})";
  const std::vector<LandmarkList> lists = readLandmarkLists(json.string());
  ASSERT_EQ(lists.size(), 2u);
  EXPECT_EQ(lists[0].name, "Caudate L");
  EXPECT_EQ(lists[0].stated, CoordinateSystem::LPS);
  ASSERT_EQ(lists[0].landmarks.size(), 2u);
  EXPECT_EQ(lists[0].landmarks[1].position, Vector3(4, 5, 6));
  EXPECT_EQ(lists[1].name, "");
  EXPECT_EQ(lists[1].stated, CoordinateSystem::RAS);
  ASSERT_EQ(lists[1].landmarks.size(), 1u);
  EXPECT_EQ(lists[1].landmarks[0].position, Vector3(-10, -20, 30));
  CoordinateSystem stated = CoordinateSystem::RAS;
  EXPECT_EQ(readLandmarks(json.string(), &stated).size(), 3u);
  EXPECT_EQ(stated, CoordinateSystem::LPS);  // the first list's

  const fs::path csv = scratch("one.csv");
  writeLandmarks(sample(), csv.string());
  const std::vector<LandmarkList> one = readLandmarkLists(csv.string());
  ASSERT_EQ(one.size(), 1u);
  EXPECT_EQ(one[0].name, "");
  EXPECT_EQ(one[0].landmarks.size(), 3u);

  // Beside one list of points, an empty list is left out (a scene's stray
  // list); beside several, it would drop its structure and shift the names
  // and labels given to those after it: it is refused.
  const fs::path stray = scratch("stray.mrk.json");
  std::ofstream(stray.string()) << R"({"markups": [{"name": "F", "controlPoints": []},
    {"name": "Putamen L", "controlPoints": [{"label": "p1", "position": [10.0, 20.0, 30.0]}]}]})";
  const std::vector<LandmarkList> kept = readLandmarkLists(stray.string());
  ASSERT_EQ(kept.size(), 1u);
  EXPECT_EQ(kept[0].name, "Putamen L");
  const fs::path gap = scratch("gap.mrk.json");
  std::ofstream(gap.string()) << R"({"markups": [
    {"name": "Caudate L", "controlPoints": []},
    {"name": "Putamen L", "controlPoints": [{"label": "p1", "position": [10.0, 20.0, 30.0]}]},
    {"name": "Thalamus L", "controlPoints": [{"label": "t1", "position": [12.0, 18.0, 8.0]}]}]})";
  try {
    readLandmarkLists(gap.string());
    FAIL() << "an empty list beside two with points was accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("gap.mrk.json: point list 1 ('Caudate L') holds no point"), std::string::npos)
        << e.what();
  }
}

// A scene's markups file may hold a ruler or a box beside the point lists:
// a curve's points are landmarks (drawn along a boundary), a line's, an
// angle's, a plane's and an ROI's are not; an unknown type is refused.
TEST(Landmarks, OnlyPointListsAndCurvesGiveLandmarks) {
  const fs::path json = scratch("scene.mrk.json");
  std::ofstream(json.string()) << R"({"markups": [
    {"type": "Line", "name": "ruler", "controlPoints": [
      {"position": [0.0, 0.0, 0.0]}, {"position": [9.0, 0.0, 0.0]}]},
    {"type": "Fiducial", "name": "Caudate L", "controlPoints": [{"position": [1.0, 2.0, 3.0]}]},
    {"type": "ROI", "name": "box", "controlPoints": [{"position": [5.0, 5.0, 5.0]}]},
    {"type": "ClosedCurve", "name": "Putamen L", "controlPoints": [
      {"position": [7.0, 8.0, 9.0]}, {"position": [7.0, 9.0, 9.0]}]},
    {"type": "Angle", "controlPoints": [{"position": [1.0, 1.0, 1.0]}]},
    {"type": "Plane", "controlPoints": [{"position": [2.0, 2.0, 2.0]}]}]})";
  const std::vector<LandmarkList> lists = readLandmarkLists(json.string());
  ASSERT_EQ(lists.size(), 2u);
  EXPECT_EQ(lists[0].name, "Caudate L");
  EXPECT_EQ(lists[1].name, "Putamen L");
  EXPECT_EQ(lists[1].landmarks.size(), 2u);
  EXPECT_EQ(readLandmarks(json.string()).size(), 3u);

  const fs::path unknown = scratch("unknown.mrk.json");
  std::ofstream(unknown.string()) << R"({"markups": [{"type": "Spline", "controlPoints": [{"position": [1, 2, 3]}]}]})";
  try {
    readLandmarks(unknown.string());
    FAIL() << "a markup of unknown type was read";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("unknown.mrk.json"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("unknown type \"Spline\""), std::string::npos) << e.what();
  }
}

TEST(Landmarks, BadFilesAreRefusedWithTheirName) {
  auto expectError = [](const fs::path& path, const std::string& fragment) {
    try {
      readLandmarks(path.string());
      FAIL() << path << " was read";
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find(path.filename().string()), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find(fragment), std::string::npos) << e.what();
    }
  };
  // `text` written as the scratch file `name`.
  auto written = [](const std::string& name, const std::string& text) {
    std::ofstream(scratch(name).string()) << text;
    return scratch(name);
  };
  expectError(scratch("none.csv"), "no such file");
  std::filesystem::create_directories(scratch("folder.mrk.json"));
  expectError(scratch("folder.mrk.json"), "is a directory");
  expectError(written("points.txt", "1 2 3\n"), "unknown landmark format");
  expectError(written("nan.csv", "x,y,z\n1,2,3\n4,nan,6\n"), "line 3");
  expectError(written("noheader.csv", "1,2,3\n"), "x, y and z");
  expectError(written("broken.mrk.json", "{\"markups\": ["), "not valid JSON: parse error at line 1");
  // Text after the document (here the document pasted twice) is refused, not ignored.
  writeLandmarks(sample(), scratch("twice.mrk.json").string());
  {
    std::ifstream in(scratch("twice.mrk.json"));
    const std::string text{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
    std::ofstream(scratch("twice.mrk.json").string()) << text << text;
  }
  expectError(scratch("twice.mrk.json"), "not valid JSON");
  EXPECT_THROW(writeLandmarks(sample(), scratch("no/such/dir/p.csv").string()), Error);

  // A column named twice, and a row of more values than the header's
  // columns: which values are x, y and z is not known.
  expectError(written("twox.csv", "x,y,z,X\n1,2,3,4\n"), "the column 'x' is named twice");
  expectError(written("fourvalues.csv", "x,y,z\n1,2,3\n1,5,2,3\n"),
              "line 3: 4 fields, but the first line names 3 columns");
  expectError(written("twox.fcsv", "# columns = id,x,y,z,x\n1,2,3,4,5\n"), "the column 'x' is named twice");
  // A header line after points would apply to some of them only.
  expectError(written("late.fcsv", "1,2,3,4\n# CoordinateSystem = RAS\n5,6,7,8\n"),
              "line 2: a header line ('CoordinateSystem') after the points: move it above them");
  // Old Mac text: one line, which names no columns.
  expectError(written("mac.csv", "x,y,z\r1,2,3\r4,5,6\r"), "a carriage return alone");
  // A markups file's fields of the wrong JSON type and states it does not have.
  expectError(written("numberlabel.mrk.json",
                      R"({"markups": [{"type": "Fiducial", "controlPoints": [{"position": [1, 2, 3], "label": 5}]}]})"),
              "control point 1: \"label\" must be a string, got 5");
  expectError(
      written(
          "status.mrk.json",
          R"({"markups": [{"type": "Fiducial", "controlPoints": [{"position": [1, 2, 3], "positionStatus": "bogus"}]}]})"),
      "unknown positionStatus \"bogus\"");
  expectError(written("notobject.mrk.json", R"({"markups": [7]})"), "markup 1 is not a JSON object");
  // Regions and measurements alone: said to be what they are.
  expectError(
      written("box.mrk.json",
              R"({"markups": [{"type": "ROI", "controlPoints": [{"position": [1, 2, 3]}]}, {"type": "Plane"}]})"),
      "its markups (ROI, Plane) are measurements or regions");
}

std::string contents(const fs::path& path) {
  std::ifstream in(path.string());
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

// What the viewer's save does to a file 3D Slicer wrote: its points change,
// nothing else does.
TEST(Landmarks, UpdatingAMarkupsFileKeepsWhatElseItHolds) {
  const fs::path json = scratch("slicer.mrk.json");
  std::ofstream(json.string()) << R"({"@schema": "x", "markups": [
    {"type": "ROI", "name": "box", "coordinateSystem": "LPS", "controlPoints": []},
    {"type": "Fiducial", "name": "caudate", "coordinateSystem": "RAS", "coordinateUnits": "mm",
     "controlPoints": [
       {"id": "7", "label": "head", "description": "checked twice", "position": [1, 2, 3], "locked": true,
        "positionStatus": "defined"},
       {"id": "8", "label": "gone", "position": [4, 5, 6], "positionStatus": "defined"},
       {"id": "9", "label": "tail", "position": [0, 0, 0], "positionStatus": "undefined"},
       {"id": 10, "label": 5, "positionStatus": "undefined"},
       {"id": "11", "description": "no label", "position": [7, 8, 9]}],
     "measurements": [], "display": {"selectedColor": [0.1, 0.9, 0.2], "glyphScale": 2.5}}]})";
  // The unlabelled point reads as F-5 (its place in the list) and keeps its
  // entry under that name. "head" moved (LPS), "gone" deleted, "new" placed.
  ASSERT_EQ(readLandmarks(json.string()).back().label, "F-5");
  updateLandmarks({{"head", Vector3(-10, -20, 30)}, {"new", Vector3(-1, -1, 1)}, {"F-5", Vector3(-7, -8, 9)}},
                  json.string());

  const std::vector<LandmarkList> lists = readLandmarkLists(json.string());
  ASSERT_EQ(lists.size(), 1u);
  EXPECT_EQ(lists[0].name, "caudate");
  EXPECT_EQ(lists[0].stated, CoordinateSystem::RAS);
  ASSERT_EQ(lists[0].landmarks.size(), 3u);
  EXPECT_EQ(lists[0].landmarks[0].label, "head");
  EXPECT_LT((lists[0].landmarks[0].position - Vector3(-10, -20, 30)).norm(), 1e-12);
  EXPECT_EQ(lists[0].landmarks[1].label, "new");
  EXPECT_LT((lists[0].landmarks[1].position - Vector3(-1, -1, 1)).norm(), 1e-12);
  const std::string text = contents(json);
  EXPECT_NE(text.find("\"box\""), std::string::npos);              // the other markup
  EXPECT_NE(text.find("\"glyphScale\": 2.5"), std::string::npos);  // the list's display
  EXPECT_NE(text.find("\"checked twice\""), std::string::npos);    // the moved point's description
  EXPECT_NE(text.find("\"label\": \"tail\""), std::string::npos);  // the name not yet placed
  EXPECT_EQ(text.find("\"gone\""), std::string::npos);
  EXPECT_NE(text.find("\"no label\""), std::string::npos);    // the unlabelled point's description
  EXPECT_EQ(text.find("\"id\": \"8\""), std::string::npos);   // a new point takes no id the list used
  EXPECT_EQ(text.find("\"id\": \"10\""), std::string::npos);  // nor a number one

  // A legacy file keeps its coordinate system; a missing one is written.
  const fs::path fcsv = scratch("slicer.fcsv");
  writeLandmarks(sample(), fcsv.string(), CoordinateSystem::RAS);
  updateLandmarks({sample()[1]}, fcsv.string());
  CoordinateSystem stated = CoordinateSystem::LPS;
  const auto read = readLandmarks(fcsv.string(), &stated);
  EXPECT_EQ(stated, CoordinateSystem::RAS);
  ASSERT_EQ(read.size(), 1u);
  EXPECT_LT((read[0].position - sample()[1].position).norm(), 1e-9);
  const fs::path fresh = scratch("fresh.mrk.json");
  fs::remove(fresh);
  updateLandmarks(sample(), fresh.string());
  EXPECT_EQ(readLandmarks(fresh.string()).size(), 3u);

  // A file of two structures cannot take one structure's points.
  const fs::path two = scratch("two.mrk.json");
  std::ofstream(two.string()) << R"({"markups": [
    {"type": "Fiducial", "name": "a", "controlPoints": [{"position": [1, 2, 3]}]},
    {"type": "Fiducial", "name": "b", "controlPoints": [{"position": [4, 5, 6]}]}]})";
  const std::string before = contents(two);
  try {
    updateLandmarks(sample(), two.string());
    ADD_FAILURE() << "a file of two lists was rewritten";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("two.mrk.json"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("2 lists"), std::string::npos) << e.what();
  }
  EXPECT_EQ(contents(two), before);
}

TEST(Landmarks, SpreadsheetFilesAreRead) {
  // Excel's "CSV UTF-8" starts with a byte order mark.
  const fs::path csv = scratch("excel.csv");
  std::ofstream(csv.string()) << "\xEF\xBB\xBFX,Y,Z,Label\n-12,10,12,head\n-14,12,10\n";
  std::ofstream(scratch("trailing.csv").string()) << "x,y,z\n1,2,3,\n4,5,6\n";
  EXPECT_EQ(readLandmarks(scratch("trailing.csv").string()).size(), 2u);
  // Comments before the header, and rows of separators alone (a
  // spreadsheet's formatted empty rows), hold no point; after the header a
  // label may start with '#'.
  std::ofstream(scratch("blank.csv").string()) << "# clicks of rater 2\nx,y,z,label\n1,2,3\n,,\n  \n4,5,6,#2\n";
  const std::vector<Landmark> blank = readLandmarks(scratch("blank.csv").string());
  ASSERT_EQ(blank.size(), 2u);
  EXPECT_EQ(blank[1].label, "#2");
  // 3D Slicer's markups table, in LPS (l, p, s) or RAS (r, a, s), its
  // unplaced points (defined 0) left out.
  std::ofstream(scratch("slicer_lps.csv").string())
      << "label,l,p,s,defined,selected,visible,locked,description\nF-1,1,2,3,1,1,1,0,\nF-2,0,0,0,0,1,1,0,\n"
      << "F-3,0,0,0,FALSE,1,1,0,\n";
  CoordinateSystem stated = CoordinateSystem::RAS;
  const std::vector<Landmark> lps = readLandmarks(scratch("slicer_lps.csv").string(), &stated);
  ASSERT_EQ(lps.size(), 1u);
  EXPECT_EQ(lps[0].position, Vector3(1, 2, 3));
  EXPECT_EQ(stated, CoordinateSystem::LPS);
  std::ofstream(scratch("slicer_ras.csv").string())
      << "label,r,a,s,defined,p\nF-1,1,2,3,1,0.5\n";  // r, a, s complete: an extra 'p' column is not an axis
  const std::vector<Landmark> ras = readLandmarks(scratch("slicer_ras.csv").string(), &stated);
  ASSERT_EQ(ras.size(), 1u);
  EXPECT_EQ(ras[0].position, Vector3(-1, -2, 3));
  EXPECT_EQ(stated, CoordinateSystem::RAS);
  const std::vector<Landmark> read = readLandmarks(csv.string());
  ASSERT_EQ(read.size(), 2u);
  EXPECT_EQ(read[0].position, Vector3(-12, 10, 12));
  EXPECT_EQ(read[0].label, "head");
  // A label with a comma keeps its row's columns through a round trip, and a
  // point that is not placed yet (Slicer's "undefined") is left out.
  for (const std::string name : {"comma.csv", "comma.fcsv", "comma.mrk.json"}) {
    writeLandmarks({{"head, left", Vector3(1, 2, 3)}}, scratch(name).string());
    const std::vector<Landmark> back = readLandmarks(scratch(name).string());
    ASSERT_EQ(back.size(), 1u) << name;
    EXPECT_EQ(back[0].label, "head, left") << name;
  }
  // Slicer's schema 1.0.3 also writes the unit as a list of its forms.
  const fs::path units = scratch("units.mrk.json");
  std::ofstream(units.string()) << R"({"markups": [{"type": "Fiducial", "coordinateUnits": ["mm", "UCUM", "millimeter"],
      "controlPoints": [{"position": [1, 2, 3]}]}]})";
  EXPECT_EQ(readLandmarks(units.string()).size(), 1u);
  const fs::path pending = scratch("pending.mrk.json");
  std::ofstream(pending.string()) << R"({"markups": [{"type": "Fiducial", "controlPoints": [
      {"position": [1, 2, 3]}, {"position": [0, 0, 0], "positionStatus": "undefined"}]}]})";
  EXPECT_EQ(readLandmarks(pending.string()).size(), 1u);
}

}  // namespace
}  // namespace dynsub
