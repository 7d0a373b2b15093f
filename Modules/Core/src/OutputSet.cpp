#include "dynsub/OutputSet.h"

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <iostream>

#include "dynsub/AtomicOutput.h"
#include "dynsub/Error.h"

namespace dynsub {

void prepareOutputDirectory(const std::filesystem::path& dir) {
  std::error_code error;
  if (std::filesystem::exists(dir, error)) {
    if (!std::filesystem::is_directory(dir, error)) throw Error(dir.string(), "exists and is not a directory");
    requireWritableDirectoryFor((dir / "report.json").string());
    return;
  }
  const std::filesystem::path parent = dir.has_parent_path() ? dir.parent_path() : std::filesystem::path(".");
  if (!std::filesystem::is_directory(parent, error)) {
    throw Error(dir.string(), "cannot be created: " + parent.string() + " does not exist");
  }
  requireWritableDirectoryFor(dir.string());
}

OutputSet::OutputSet(std::filesystem::path dir) : dir_(std::move(dir)) {
  std::error_code error;
  if (!std::filesystem::exists(dir_, error)) {
    if (!std::filesystem::create_directory(dir_, error)) throw Error(dir_.string(), "cannot be created: " + error.message());
    created_ = true;
  }
  // Two runs writing to one directory at once take turns: each holds a lock
  // on the directory from its first file to its commit, so their files never
  // interleave (the last run's set is the one that stays whole).
  lock_ = ::open(dir_.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (lock_ < 0) throw Error(dir_.string(), "cannot be opened: " + std::string(std::strerror(errno)));
  if (::flock(lock_, LOCK_EX | LOCK_NB) != 0) {
    std::cerr << "dynsub: waiting for another run writing to " << dir_.string() << '\n';
    while (::flock(lock_, LOCK_EX) != 0 && errno == EINTR) {
    }
  }
}

OutputSet::~OutputSet() {
  outputs_.clear();  // removes uncommitted temporary files
  if (created_ && !committed_) {
    std::error_code error;
    std::filesystem::remove(dir_, error);
  }
  if (lock_ >= 0) ::close(lock_);  // releases the lock
}

std::string OutputSet::add(const std::string& name) {
  outputs_.push_back(std::make_unique<AtomicOutput>((dir_ / name).string()));
  return outputs_.back()->temporaryPath();
}

void OutputSet::commit() {
  for (auto& output : outputs_) output->commit();
  committed_ = true;
}

}  // namespace dynsub
