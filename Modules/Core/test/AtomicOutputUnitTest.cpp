// Unit test (no rendering): an output is either complete or absent.
#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>

#include "dynsub/AtomicOutput.h"
#include "dynsub/Error.h"

namespace fs = std::filesystem;

namespace {

fs::path freshDirectory(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / ("dynsub-" + name);
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

TEST(AtomicOutput, CommitMovesTheFileIntoPlace) {
  const fs::path dir = freshDirectory("atomic-commit");
  const std::string target = (dir / "out.obj").string();
  {
    dynsub::AtomicOutput output(target);
    EXPECT_EQ(fs::path(output.temporaryPath()).extension(), ".obj");
    std::ofstream(output.temporaryPath()) << "v 0 0 0\n";
    EXPECT_FALSE(fs::exists(target));
    output.commit();
  }
  EXPECT_TRUE(fs::exists(target));
  EXPECT_EQ(std::distance(fs::directory_iterator(dir), fs::directory_iterator()), 1);
}

TEST(AtomicOutput, AbandonedOutputLeavesNothing) {
  const fs::path dir = freshDirectory("atomic-abandon");
  const std::string target = (dir / "out.vtp").string();
  {
    dynsub::AtomicOutput output(target);
    std::ofstream(output.temporaryPath()) << "half";
  }
  EXPECT_FALSE(fs::exists(target));
  EXPECT_TRUE(fs::is_empty(dir));
}

TEST(AtomicOutput, MissingDirectoryIsNamed) {
  try {
    dynsub::AtomicOutput output("/nonexistent-dynsub-dir/out.obj");
    FAIL() << "expected an error";
  } catch (const dynsub::Error& error) {
    EXPECT_NE(std::string(error.what()).find("/nonexistent-dynsub-dir"), std::string::npos);
  }
}

}  // namespace
