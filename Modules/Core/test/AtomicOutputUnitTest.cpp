// Unit test (no rendering): an output is either complete or absent.
#include <sys/wait.h>
#include <unistd.h>

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

// A writer that opens its own output on an enclosing output's temporary path
// writes there directly (no ".tmp-<pid>-.tmp-<pid>-" file), and only the
// enclosing output makes the target appear.
TEST(AtomicOutput, NestedOutputsShareOneTemporaryFile) {
  const fs::path dir = freshDirectory("atomic-nested");
  const std::string target = (dir / "surface.vtp").string();
  {
    dynsub::AtomicOutput outer(target);
    {
      dynsub::AtomicOutput inner(outer.temporaryPath());
      EXPECT_EQ(inner.temporaryPath(), outer.temporaryPath());
      std::ofstream(inner.temporaryPath()) << "data";
      inner.commit();
    }
    EXPECT_TRUE(fs::exists(outer.temporaryPath()));
    EXPECT_FALSE(fs::exists(target));
    outer.commit();
  }
  EXPECT_TRUE(fs::exists(target));
  EXPECT_EQ(std::distance(fs::directory_iterator(dir), fs::directory_iterator()), 1);
  // Abandoned, the enclosing output still removes the shared file.
  const std::string other = (dir / "labels.nii.gz").string();
  {
    dynsub::AtomicOutput outer(other);
    dynsub::AtomicOutput inner(outer.temporaryPath());
    std::ofstream(inner.temporaryPath()) << "half";
  }
  EXPECT_EQ(std::distance(fs::directory_iterator(dir), fs::directory_iterator()), 1);
}

// A run killed before committing leaves ".tmp-<pid>-<name>"; the next output
// of that name removes it once that process is gone, and leaves a live
// process's (a concurrent run's) and other names' alone.
TEST(AtomicOutput, TheNextRunRemovesTemporariesOfKilledRuns) {
  const fs::path dir = freshDirectory("atomic-stale");
  const pid_t child = fork();
  if (child == 0) _exit(0);
  ASSERT_GT(child, 0);
  int status = 0;
  waitpid(child, &status, 0);  // gone: its pid names a killed run
  const fs::path stale = dir / (".tmp-" + std::to_string(child) + "-report.json");
  const fs::path live = dir / (".tmp-" + std::to_string(getppid()) + "-report.json");
  const fs::path otherName = dir / (".tmp-" + std::to_string(child) + "-surface.vtp");
  for (const fs::path& p : {stale, live, otherName}) std::ofstream(p) << "partial";
  {
    dynsub::AtomicOutput output((dir / "report.json").string());
    std::ofstream(output.temporaryPath()) << "{}";
    output.commit();
  }
  EXPECT_FALSE(fs::exists(stale));
  EXPECT_TRUE(fs::exists(live));
  EXPECT_TRUE(fs::exists(otherName));
  EXPECT_TRUE(fs::exists(dir / "report.json"));
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
