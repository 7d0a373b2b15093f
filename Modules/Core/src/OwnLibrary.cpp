#include "dynsub/OwnLibrary.h"

#include <dlfcn.h>

#include <filesystem>
#include <vector>

#include "dynsub/Error.h"

namespace dynsub {

namespace fs = std::filesystem;

void* openOwnLibrary(const std::string& name, const std::string& buildPath, const char* symbol,
                     const std::string& purpose) {
  std::vector<fs::path> candidates;
  std::error_code ignored;
  const fs::path program = fs::read_symlink("/proc/self/exe", ignored);
  if (!program.empty()) candidates.push_back(program.parent_path().parent_path() / "lib" / name);
  candidates.push_back(buildPath);
  std::string failures;
  for (const fs::path& candidate : candidates) {
    if (!fs::exists(candidate, ignored)) continue;
    void* library = dlopen(candidate.c_str(), RTLD_NOW | RTLD_LOCAL);
    if (library == nullptr) {
      failures += std::string("; ") + dlerror();
      continue;
    }
    void* entry = dlsym(library, symbol);
    if (entry == nullptr) throw Error(candidate.string(), "not DynSub's " + purpose + ": " + dlerror());
    return entry;
  }
  std::string places;
  for (const fs::path& candidate : candidates) {
    const std::string place = candidate.parent_path().string();
    if (places.find(place) == std::string::npos) places += (places.empty() ? "" : ", ") + place;
  }
  throw Error(name, "cannot open the " + purpose + " (looked in " + places + ")" + failures);
}

}  // namespace dynsub
