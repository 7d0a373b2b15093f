// Unit test (no rendering): an output, or a set of outputs, is either complete or absent.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <csignal>
#include <filesystem>
#include <fstream>
#include <string>
#include <thread>
#include <vector>

#include "dynsub/AtomicOutput.h"
#include "dynsub/Error.h"
#include "dynsub/OutputSet.h"

namespace fs = std::filesystem;

namespace {

fs::path freshDirectory(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / ("dynsub-" + name);
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

// The pid of a process that has ended: the pid a killed run's temporaries
// are named by.
pid_t endedProcess() {
  const pid_t child = fork();
  if (child == 0) _exit(0);
  int status = 0;
  if (child > 0) waitpid(child, &status, 0);
  return child;
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
  const pid_t child = endedProcess();  // its pid names a killed run
  ASSERT_GT(child, 0);
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

std::size_t entries(const fs::path& dir) {
  return static_cast<std::size_t>(std::distance(fs::directory_iterator(dir), fs::directory_iterator()));
}

// A new directory is written as a folder beside it and appears in one
// rename, with its files and its folders (an output set inside it), so a
// run killed at any moment leaves it absent or whole.
TEST(OutputSet, ANewDirectoryAppearsWholeAtCommit) {
  const fs::path parent = freshDirectory("set-new");
  const fs::path dir = parent / "out";
  {
    dynsub::OutputSet outputs(dir);
    std::ofstream(outputs.add("report.json")) << "{}";
    {
      dynsub::OutputSet inner(outputs.writingDirectory() / "caudate");
      std::ofstream(inner.add("surface.vtp")) << "<VTKFile/>";
      inner.commit();
    }
    EXPECT_FALSE(fs::exists(dir));
    EXPECT_EQ(entries(parent), 1u);  // the set's own folder, .tmp-<pid>-out
    outputs.commit();
  }
  EXPECT_EQ(entries(parent), 1u);
  EXPECT_TRUE(fs::exists(dir / "report.json"));
  EXPECT_TRUE(fs::exists(dir / "caudate" / "surface.vtp"));
  EXPECT_EQ(entries(dir), 2u);
  EXPECT_EQ(entries(dir / "caudate"), 1u);
}

// A shell's completion writes "out/": it names the folder "out", whether or
// not it exists yet; a missing parent is still refused.
TEST(OutputSet, ATrailingSlashNamesTheFolder) {
  const fs::path parent = freshDirectory("set-slash");
  const fs::path slashed = fs::path((parent / "out").string() + "/");
  EXPECT_NO_THROW(dynsub::prepareOutputDirectory(slashed));
  {
    dynsub::OutputSet outputs(slashed);
    std::ofstream(outputs.add("report.json")) << "{}";
    outputs.commit();
  }
  EXPECT_TRUE(fs::exists(parent / "out" / "report.json"));
  EXPECT_NO_THROW(dynsub::prepareOutputDirectory(slashed));
  EXPECT_THROW(dynsub::prepareOutputDirectory(fs::path((parent / "missing" / "out").string() + "/")), dynsub::Error);
}

TEST(OutputSet, WithoutCommitNothingIsLeft) {
  const fs::path parent = freshDirectory("set-abandon");
  {
    dynsub::OutputSet outputs(parent / "out");
    std::ofstream(outputs.add("report.json")) << "{}";
  }
  EXPECT_EQ(entries(parent), 0u);
  fs::create_directory(parent / "existing");
  {
    dynsub::OutputSet outputs(parent / "existing");
    std::ofstream(outputs.add("report.json")) << "{}";
  }
  EXPECT_EQ(entries(parent / "existing"), 0u);
}

// Into a directory that exists, the files are renamed into it; the other
// files there stay.
TEST(OutputSet, AnExistingDirectoryKeepsItsOtherFiles) {
  const fs::path dir = freshDirectory("set-existing");
  std::ofstream(dir / "notes.txt") << "mine";
  std::ofstream(dir / "report.json") << "old";
  {
    dynsub::OutputSet outputs(dir);
    std::ofstream(outputs.add("report.json")) << "new";
    outputs.commit();
  }
  EXPECT_EQ(entries(dir), 2u);
  std::string text;
  std::ifstream(dir / "report.json") >> text;
  EXPECT_EQ(text, "new");
}

// A file or folder the set retires (one it writes only sometimes) is gone
// after the commit, not before it; the other files stay, and so does one the
// set retires and adds.
TEST(OutputSet, ARetiredFileOfAnEarlierRunIsRemovedAtCommit) {
  const fs::path dir = freshDirectory("set-retired");
  std::ofstream(dir / "notes.txt") << "mine";
  std::ofstream(dir / "outliers.xyz") << "1 2 3";
  fs::create_directories(dir / "putamen" / "figures");
  std::ofstream(dir / "putamen" / "report.json") << "{}";
  {
    dynsub::OutputSet outputs(dir);
    std::ofstream(outputs.add("report.json")) << "{}";
    outputs.retire("outliers.xyz");
    outputs.retire("putamen");
    outputs.retire("never-written.xyz");  // absent: nothing to do
    outputs.retire("report.json");        // added too: the new one stays
    EXPECT_TRUE(fs::exists(dir / "outliers.xyz"));
    EXPECT_TRUE(fs::exists(dir / "putamen" / "report.json"));
    outputs.commit();
  }
  EXPECT_FALSE(fs::exists(dir / "outliers.xyz"));
  EXPECT_FALSE(fs::exists(dir / "putamen"));
  EXPECT_TRUE(fs::exists(dir / "notes.txt"));
  EXPECT_TRUE(fs::exists(dir / "report.json"));
  {
    // The same in a new directory, written in its staging folder first.
    const fs::path fresh = dir / "fresh";
    dynsub::OutputSet outputs(fresh);
    std::ofstream(outputs.add("report.json")) << "{}";
    outputs.retire("report.json");
    outputs.commit();
    EXPECT_TRUE(fs::exists(fresh / "report.json"));
  }
  {
    dynsub::OutputSet outputs(dir);  // without commit() nothing is removed
    std::ofstream(dir / "outliers.xyz") << "1 2 3";
    outputs.retire("outliers.xyz");
  }
  EXPECT_TRUE(fs::exists(dir / "outliers.xyz"));
}

// Another run made the directory while this set was written: the set moves
// in over that run's, a folder of the same name replaced whole.
TEST(OutputSet, ADirectoryMadeMeanwhileTakesTheSet) {
  const fs::path parent = freshDirectory("set-meanwhile");
  const fs::path dir = parent / "out";
  {
    dynsub::OutputSet outputs(dir);
    {
      dynsub::OutputSet inner(outputs.writingDirectory() / "caudate");
      std::ofstream(inner.add("surface.vtp")) << "second";
      inner.commit();
    }
    std::ofstream(outputs.add("report.json")) << "second";
    fs::create_directories(dir / "caudate");
    std::ofstream(dir / "caudate" / "surface.vtp") << "first";
    std::ofstream(dir / "caudate" / "labelmap.nii.gz") << "first";
    std::ofstream(dir / "report.json") << "first";
    std::ofstream(dir / "labelmap.nii.gz") << "first";
    outputs.commit();
  }
  EXPECT_EQ(entries(parent), 1u);
  EXPECT_EQ(entries(dir), 3u);  // caudate, report.json and the first run's labelmap.nii.gz
  EXPECT_EQ(entries(dir / "caudate"), 1u);
  std::string text;
  std::ifstream(dir / "report.json") >> text;
  EXPECT_EQ(text, "second");
  std::ifstream(dir / "caudate" / "surface.vtp") >> text;
  EXPECT_EQ(text, "second");
}

// A folder an earlier process with this pid left (pids are reused) does
// not stop the set.
TEST(OutputSet, AFolderLeftUnderThisPidIsReplaced) {
  const fs::path parent = freshDirectory("set-same-pid");
  fs::create_directories(parent / dynsub::temporaryName("out"));
  std::ofstream(parent / dynsub::temporaryName("out") / "surface.vtp") << "old";
  {
    dynsub::OutputSet outputs(parent / "out");
    std::ofstream(outputs.add("report.json")) << "{}";
    outputs.commit();
  }
  EXPECT_EQ(entries(parent), 1u);
  EXPECT_EQ(entries(parent / "out"), 1u);
}

// A killed run's folder is swept by the next set of the same directory.
TEST(OutputSet, TheNextRunRemovesTheFolderOfAKilledRun) {
  const fs::path parent = freshDirectory("set-stale");
  const pid_t child = endedProcess();
  ASSERT_GT(child, 0);
  const fs::path stale = parent / (".tmp-" + std::to_string(child) + "-out");
  fs::create_directories(stale / "caudate");
  std::ofstream(stale / "caudate" / "surface.vtp") << "partial";
  {
    dynsub::OutputSet outputs(parent / "out");
    std::ofstream(outputs.add("report.json")) << "{}";
    outputs.commit();
  }
  EXPECT_FALSE(fs::exists(stale));
  EXPECT_EQ(entries(parent), 1u);
  // Also when the directory is there by now (a rerun into it).
  fs::create_directories(stale);
  {
    dynsub::OutputSet outputs(parent / "out");
    std::ofstream(outputs.add("report.json")) << "{}";
    outputs.commit();
  }
  EXPECT_FALSE(fs::exists(stale));
}

// Interrupted (Ctrl-C, a scheduler's SIGTERM, a closed terminal's SIGHUP), a
// process that called removeTemporariesOnInterrupt removes its outputs in
// progress, a file and a new directory's folder with files in it, keeps what
// it had committed, and ends by the signal. Also when the signal lands on a
// thread that was running before the call and does not block it, as a BLAS
// library's thread pool started when the library was loaded.
TEST(AtomicOutput, AnInterruptRemovesOutputsInProgress) {
  for (const bool earlierThread : {false, true})
    for (const int signal : {SIGINT, SIGTERM, SIGHUP}) {
      const std::string which = "signal " + std::to_string(signal) + (earlierThread ? " to an earlier thread" : "");
      const fs::path dir = freshDirectory("atomic-interrupt");
      int ready[2];
      ASSERT_EQ(pipe(ready), 0);
      const pid_t child = fork();
      ASSERT_GE(child, 0);
      if (child == 0) {
        close(ready[0]);
        std::thread earlier;
        if (earlierThread)
          earlier = std::thread([] {
            for (;;) pause();
          });
        dynsub::removeTemporariesOnInterrupt();
        {
          dynsub::AtomicOutput done((dir / "done.obj").string());
          std::ofstream(done.temporaryPath()) << "v 0 0 0\n";
          done.commit();
        }
        dynsub::AtomicOutput file((dir / "surface.obj").string());
        std::ofstream(file.temporaryPath()) << "v 0 0 0\n";
        dynsub::OutputSet set(dir / "run");
        std::ofstream(set.add("report.json")) << "{}";
        fs::create_directory(set.writingDirectory() / "structure");
        std::ofstream(set.writingDirectory() / "structure" / "labelmap.nii.gz") << "half";
        if (write(ready[1], "r", 1) != 1) _exit(3);
        if (earlierThread) pthread_kill(earlier.native_handle(), signal);
        for (;;) pause();
      }
      close(ready[1]);
      char byte = 0;
      ASSERT_EQ(read(ready[0], &byte, 1), 1) << "the child did not get as far as its outputs";
      close(ready[0]);
      if (!earlierThread) {
        ASSERT_EQ(kill(child, signal), 0);
      }
      int status = 0;
      ASSERT_EQ(waitpid(child, &status, 0), child);
      ASSERT_TRUE(WIFSIGNALED(status)) << which << ": the child exited with " << WEXITSTATUS(status);
      EXPECT_EQ(WTERMSIG(status), signal) << which;
      std::vector<std::string> left;
      for (const auto& entry : fs::directory_iterator(dir)) left.push_back(entry.path().filename().string());
      EXPECT_EQ(left, std::vector<std::string>{"done.obj"}) << which;
    }
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
