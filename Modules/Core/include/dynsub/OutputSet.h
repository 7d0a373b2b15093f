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

// Files in one directory that appear together, or not at all.
//  - A directory that does not exist yet is written as a folder of its own
//    beside it, ".tmp-<pid>-<name>", renamed into place by commit(): it
//    appears whole, with every file and folder of the set, in one step. A
//    killed run leaves only that folder, which the next set of the same
//    directory sweeps (AtomicOutput.h). Should another run have made the
//    directory meanwhile, the set moves in over that run's: its folders
//    (each replacing one of the same name), then its files one by one, in
//    the order added.
//  - Into a directory that exists, each file is written to a temporary file
//    beside its target, and commit() renames them one by one: a run killed
//    in that instant can leave some files new and some old. The set holds an
//    exclusive lock (flock) on the directory from its start to its end, so
//    the sets of two runs writing there at once never interleave.
// Without commit() (an error, an exception) nothing of the set is left.
class OutputSet {
 public:
  explicit OutputSet(std::filesystem::path dir);
  ~OutputSet();
  OutputSet(const OutputSet&) = delete;
  OutputSet& operator=(const OutputSet&) = delete;
  // The temporary path to write `name` to.
  std::string add(const std::string& name);
  // A file or folder an earlier run may have left in the directory that
  // this run must not leave behind (a fit's outliers.xyz when none were set
  // aside, a structure's folder of an earlier run of other structures): it
  // is removed at commit(), so that it is not read as this run's. A name the
  // set adds as well is kept: the set's own file replaces the earlier one.
  void retire(const std::string& name);
  // Where the set is written until commit(): a folder made in it (an
  // OutputSet of its own) becomes part of the set.
  const std::filesystem::path& writingDirectory() const { return staging_.empty() ? dir_ : staging_; }
  void commit();

 private:
  void lock(const std::filesystem::path& dir);

  std::filesystem::path dir_;
  std::filesystem::path staging_;  // the folder written in place of a new dir_, else empty
  bool committed_ = false;
  int lock_ = -1;  // the directory, opened to hold its lock
  std::vector<std::unique_ptr<AtomicOutput>> outputs_;
  std::vector<std::string> retired_;
};

}  // namespace dynsub
