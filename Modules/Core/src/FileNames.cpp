#include "dynsub/FileNames.h"

#include <filesystem>

#include "dynsub/Error.h"
#include "dynsub/TextFields.h"

namespace dynsub {

std::string lowerCaseExtension(const std::string& path) {
  return lowerCase(std::filesystem::path(path).extension().string());
}

void requireNotInput(const std::string& output, const std::string& input) {
  if (output.empty() || input.empty()) return;
  std::error_code error;
  if (std::filesystem::equivalent(output, input, error))
    throw UsageError(output, "is an input of this run too" + (input == output ? "" : " (" + input + ")") +
                                 ", which writing it would destroy: give the output another name or directory");
}

void requireExisting(const std::string& path) {
  std::error_code ignored;
  if (!std::filesystem::exists(path, ignored)) throw Error(path, "no such file or directory");
}

std::ifstream openForReading(const std::string& path, std::ios::openmode mode) {
  std::error_code ignored;
  if (!std::filesystem::exists(path, ignored)) throw Error(path, "no such file");
  if (std::filesystem::is_directory(path, ignored)) throw Error(path, "is a directory, not a file");
  std::ifstream in(path, mode);
  if (!in) throw Error(path, "cannot open the file for reading");
  return in;
}

}  // namespace dynsub
