#include "dynsub/OutputSet.h"

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <iostream>

#include "dynsub/AtomicOutput.h"
#include "dynsub/Error.h"

namespace dynsub {

void prepareOutputDirectory(const std::filesystem::path& given) {
  if (given.empty()) throw Error("the output directory's name is empty");
  // "out/" names the folder "out", as in OutputSet.
  const std::filesystem::path dir = given.has_filename() ? given : given.parent_path();
  std::error_code error;
  if (std::filesystem::exists(dir, error)) {
    if (!std::filesystem::is_directory(dir, error)) throw Error(dir.string(), "exists and is not a directory");
    requireWritableDirectoryFor((dir / "report.json").string());
    return;
  }
  const std::filesystem::path parent = dir.has_parent_path() ? dir.parent_path() : std::filesystem::path(".");
  if (!std::filesystem::is_directory(parent, error)) {
    if (std::filesystem::exists(parent, error))
      throw Error(dir.string(), "cannot be created: " + parent.string() + " is a file, not a directory");
    throw Error(dir.string(), "cannot be created: " + parent.string() + " does not exist");
  }
  requireWritableDirectoryFor(dir.string());
}

OutputSet::OutputSet(std::filesystem::path dir) : dir_(std::move(dir)) {
  // "out/" names the folder "out".
  if (!dir_.has_filename()) dir_ = dir_.parent_path();
  const std::filesystem::path parent = dir_.has_parent_path() ? dir_.parent_path() : std::filesystem::path(".");
  const std::string name = dir_.filename().string();
  removeStaleTemporaries(parent, name);  // a killed run's folder, whether or not it got as far as dir_
  std::error_code error;
  if (std::filesystem::exists(dir_, error)) {
    lock(dir_);
    return;
  }
  staging_ = parent / temporaryName(name);
  // One left by an earlier process with this pid (pids are reused) is stale.
  std::filesystem::remove_all(staging_, error);
  if (!std::filesystem::create_directory(staging_, error))
    throw Error(dir_.string(), "cannot be created: " + (error ? error.message() : staging_.string() + " exists"));
  trackTemporary(staging_.string());
}

// Two runs writing to one directory at once take turns: each holds a lock on
// the directory until its set is in place, so their files never interleave
// (the last run's set is the one that stays whole).
void OutputSet::lock(const std::filesystem::path& dir) {
  lock_ = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (lock_ < 0) throw Error(dir.string(), "cannot be opened: " + std::string(std::strerror(errno)));
  if (::flock(lock_, LOCK_EX | LOCK_NB) != 0) {
    std::cerr << "dynsub: waiting for another run writing to " << dir.string() << '\n';
    while (::flock(lock_, LOCK_EX) != 0 && errno == EINTR) {
    }
  }
}

OutputSet::~OutputSet() {
  outputs_.clear();  // removes uncommitted temporary files
  if (!staging_.empty() && !committed_) {
    std::error_code ignored;
    std::filesystem::remove_all(staging_, ignored);
  }
  if (!staging_.empty()) untrackTemporary(staging_.string());
  if (lock_ >= 0) ::close(lock_);  // releases the lock
}

std::string OutputSet::add(const std::string& name) {
  outputs_.push_back(std::make_unique<AtomicOutput>((writingDirectory() / name).string()));
  return outputs_.back()->temporaryPath();
}

void OutputSet::retire(const std::string& name) { retired_.push_back(name); }

void OutputSet::commit() {
  for (auto& output : outputs_) output->commit();
  if (!staging_.empty()) {
    std::error_code error;
    std::filesystem::rename(staging_, dir_, error);
    if (error) {
      if (!std::filesystem::is_directory(dir_))
        throw Error(dir_.string(), "cannot move the finished outputs into place: " + error.message());
      // Another run made the directory meanwhile: this set moves in over
      // that run's, its folders first (one of the same name is moved aside
      // and removed), then its files in the order they were added, so that
      // the last added (a report) arrives last.
      lock(dir_);
      std::vector<std::filesystem::path> folders;
      for (std::filesystem::directory_iterator it(staging_, error), end; !error && it != end; it.increment(error))
        if (it->is_directory()) folders.push_back(it->path());
      if (error) throw Error(staging_.string(), "cannot be read: " + error.message());
      const auto moveIn = [&](const std::filesystem::path& from) {
        const std::filesystem::path target = dir_ / from.filename();
        std::filesystem::rename(from, target, error);
        if (error) throw Error(target.string(), "cannot move the finished output into place: " + error.message());
      };
      for (const std::filesystem::path& folder : folders) {
        const std::filesystem::path target = dir_ / folder.filename();
        const std::filesystem::path aside = dir_ / temporaryName("replaced-" + folder.filename().string());
        if (std::filesystem::exists(target)) {
          std::filesystem::rename(target, aside, error);
          if (error) throw Error(target.string(), "cannot be replaced: " + error.message());
        }
        moveIn(folder);
        std::filesystem::remove_all(aside, error);
      }
      for (const auto& output : outputs_) moveIn(output->target());
      std::filesystem::remove(staging_, error);
    }
  }
  // After the set's own files: a run killed before this leaves the old file
  // beside a complete new set, never a set without it.
  for (const std::string& name : retired_) {
    const auto added = [&name](const auto& output) {
      return std::filesystem::path(output->target()).filename() == name;
    };
    if (std::any_of(outputs_.begin(), outputs_.end(), added)) continue;
    std::error_code error;
    std::filesystem::remove_all(dir_ / name, error);
    if (error) throw Error((dir_ / name).string(), "an earlier run's output cannot be removed: " + error.message());
  }
  committed_ = true;
}

}  // namespace dynsub
