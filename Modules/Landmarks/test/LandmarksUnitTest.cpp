#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

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
  expectError(scratch("none.csv"), "no such file");
  std::ofstream(scratch("points.txt").string()) << "1 2 3\n";
  expectError(scratch("points.txt"), "unknown landmark format");
  std::ofstream(scratch("nan.csv").string()) << "x,y,z\n1,2,3\n4,nan,6\n";
  expectError(scratch("nan.csv"), "line 3");
  std::ofstream(scratch("noheader.csv").string()) << "1,2,3\n";
  expectError(scratch("noheader.csv"), "x, y and z");
  std::ofstream(scratch("broken.mrk.json").string()) << "{\"markups\": [";
  expectError(scratch("broken.mrk.json"), "JSON");
  EXPECT_THROW(writeLandmarks(sample(), scratch("no/such/dir/p.csv").string()), Error);
}

}  // namespace
}  // namespace dynsub
