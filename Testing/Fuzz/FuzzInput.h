#pragma once
// What every fuzz target shares: the readers take file names, so each input
// is written to a file (under $TMPDIR, a tmpfs in ./run fuzz) with the
// extension that picks the format, and removed afterwards.
//
// The property every target checks: a reader either returns a result whose
// numbers are all finite, or throws dynsub::Error. Any other exception, a
// crash, a hang, a leak or a sanitizer report is a finding (libFuzzer turns
// an uncaught exception into an abort).
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <unistd.h>

#include "dynsub/Error.h"

namespace dynsub::fuzz {

class InputFile {
 public:
  InputFile(const std::uint8_t* data, std::size_t size, const std::string& extension) {
    const char* tmp = std::getenv("TMPDIR");
    directory_ = std::filesystem::path(tmp && *tmp ? tmp : "/tmp") / ("dynsub-fuzz-" + std::to_string(getpid()));
    std::filesystem::create_directories(directory_);
    path_ = (directory_ / ("input" + extension)).string();
    std::ofstream out(path_, std::ios::binary | std::ios::trunc);
    out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
    if (!out) {
      std::perror(path_.c_str());
      std::abort();  // the harness, not the reader, failed
    }
  }
  ~InputFile() {
    std::error_code ignored;
    std::filesystem::remove_all(directory_, ignored);
  }
  InputFile(const InputFile&) = delete;
  InputFile& operator=(const InputFile&) = delete;

  const std::string& path() const { return path_; }
  const std::filesystem::path& directory() const { return directory_; }

 private:
  std::filesystem::path directory_;
  std::string path_;
};

// Aborts (a finding) when a reader returned a number that is not finite.
template <class Matrix>
void requireFinite(const Matrix& values) {
  if (!values.allFinite()) {
    std::fputs("a reader returned a value that is not finite\n", stderr);
    std::abort();
  }
}

// A refusal is an expected outcome; DYNSUB_FUZZ_VERBOSE=1 prints its message
// (to see what the seeds and findings exercise).
inline void refused(const Error& error) {
  static const bool verbose = std::getenv("DYNSUB_FUZZ_VERBOSE") != nullptr;
  if (verbose) std::fprintf(stderr, "refused: %s\n", error.what());
}

// The first bytes of the input, to tell formats that share a target apart
// (so that files from Data/ serve as seeds as they are).
inline bool startsWith(const std::uint8_t* data, std::size_t size, const std::string& prefix) {
  return size >= prefix.size() && std::string(reinterpret_cast<const char*>(data), prefix.size()) == prefix;
}

}  // namespace dynsub::fuzz
