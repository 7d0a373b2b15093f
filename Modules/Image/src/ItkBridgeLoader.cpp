// Opens libDynSubItkBridge.so (ItkBridge.h says why it is a library of its own).
#include "ItkBridge.h"

#include <dlfcn.h>

#include <filesystem>
#include <string>
#include <vector>

#include "dynsub/Error.h"

namespace dynsub::itkbridge {
namespace {

namespace fs = std::filesystem;

const Functions* load() {
  // Beside the program, as the build lays it out (bin/ and lib/); then where
  // this build put it, for a program copied elsewhere.
  std::vector<fs::path> candidates;
  std::error_code ignored;
  const fs::path program = fs::read_symlink("/proc/self/exe", ignored);
  if (!program.empty()) candidates.push_back(program.parent_path().parent_path() / "lib" / DYNSUB_ITK_BRIDGE_NAME);
  candidates.push_back(DYNSUB_ITK_BRIDGE_BUILD_PATH);
  std::string failures;
  for (const fs::path& candidate : candidates) {
    if (!fs::exists(candidate, ignored)) continue;
    void* library = dlopen(candidate.c_str(), RTLD_NOW | RTLD_LOCAL);
    if (library == nullptr) {
      failures += std::string("; ") + dlerror();
      continue;
    }
    // Never closed: ITK's factories and GDCM's dictionary live until exit.
    using Entry = const Functions* (*)();
    const auto entry = reinterpret_cast<Entry>(dlsym(library, kFunctionsSymbol));
    if (entry == nullptr) throw Error(candidate.string(), std::string("not DynSub's ITK bridge: ") + dlerror());
    return entry();
  }
  std::string places;
  for (const fs::path& candidate : candidates) {
    const std::string place = candidate.parent_path().string();
    if (places.find(place) == std::string::npos) places += (places.empty() ? "" : ", ") + place;
  }
  throw Error(DYNSUB_ITK_BRIDGE_NAME, "cannot open the library that reads and filters images through ITK (looked in " +
                                          places + ")" + failures);
}

}  // namespace

const Functions& functions() {
  static const Functions* const loaded = load();
  return *loaded;
}

}  // namespace dynsub::itkbridge
