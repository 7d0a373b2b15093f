#pragma once
// A command's outputs in one directory, appearing together or not at all:
// AtomicOutput for a set of files.
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

namespace dynsub {

class AtomicOutput;

// Throws dynsub::Error unless `dir` is a directory or can be created (its parent exists).
void prepareOutputDirectory(const std::filesystem::path& dir);

// Files in one directory that appear together: each is written to a temporary
// file, and commit() renames them all; before that nothing is visible (a
// directory this created is removed again if commit() is never reached). A
// set holds an exclusive lock (flock) on its directory for its lifetime, so
// the sets of two runs writing there at once never interleave.
class OutputSet {
 public:
  explicit OutputSet(std::filesystem::path dir);
  ~OutputSet();
  OutputSet(const OutputSet&) = delete;
  OutputSet& operator=(const OutputSet&) = delete;
  // The temporary path to write `name` to.
  std::string add(const std::string& name);
  void commit();

 private:
  std::filesystem::path dir_;
  bool created_ = false;
  bool committed_ = false;
  int lock_ = -1;  // the directory, opened to hold its lock
  std::vector<std::unique_ptr<AtomicOutput>> outputs_;
};

}  // namespace dynsub
