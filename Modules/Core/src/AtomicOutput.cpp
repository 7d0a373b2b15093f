#include "dynsub/AtomicOutput.h"

#include <filesystem>
#include <system_error>
#include <unistd.h>

#include "dynsub/Error.h"

namespace fs = std::filesystem;

namespace dynsub {

AtomicOutput::AtomicOutput(std::string target) : target_(std::move(target)) {
  requireWritableDirectoryFor(target_);
  const fs::path path(target_);
  // The process id keeps two concurrent runs from sharing a temporary file; the
  // name ends with the target's file name, so writers still see its extension.
  temporary_ = (path.parent_path() /
                (".tmp-" + std::to_string(::getpid()) + "-" + path.filename().string()))
                   .string();
}

AtomicOutput::~AtomicOutput() {
  if (!committed_) {
    std::error_code ignored;
    fs::remove(temporary_, ignored);
  }
}

void AtomicOutput::commit() {
  std::error_code error;
  if (!fs::exists(temporary_, error)) {
    throw Error(target_, "the writer produced no output");
  }
  fs::rename(temporary_, target_, error);
  if (error) {
    throw Error(target_, "cannot move the finished output into place: " + error.message());
  }
  committed_ = true;
}

void requireWritableDirectoryFor(const std::string& path) {
  fs::path directory = fs::path(path).parent_path();
  if (directory.empty()) directory = ".";
  std::error_code error;
  if (!fs::is_directory(directory, error)) {
    throw Error(path, "the output directory '" + directory.string() + "' does not exist");
  }
  if (::access(directory.c_str(), W_OK) != 0) {
    throw Error(path, "the output directory '" + directory.string() + "' is not writable");
  }
}

}  // namespace dynsub
