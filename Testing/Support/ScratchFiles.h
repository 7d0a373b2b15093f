#pragma once
// Files a test writes: under the build tree's Testing/Temporary/<directory>/,
// which is created when first asked for (DYNSUB_BINARY_DIR comes from
// dynsub_add_test).
#include <filesystem>
#include <string>

namespace dynsub {

inline std::filesystem::path scratchFile(const std::string& directory, const std::string& name) {
  const std::filesystem::path dir = std::filesystem::path(DYNSUB_BINARY_DIR) / "Testing" / "Temporary" / directory;
  std::filesystem::create_directories(dir);
  return dir / name;
}

}  // namespace dynsub
