#pragma once
// DynSub's own shared libraries, opened when a program first needs them:
// the ITK bridge (Image module) and the rendering library (Interaction
// module). Each holds heavy third-party libraries that most runs never use,
// and loading those at every start cost every command (Documentation/
// Performance.md).
#include <string>

namespace dynsub {

// Opens `name`, looked for in lib/ beside the program's bin/ (the build's and
// an installation's layout), then at `buildPath` (where this build put it,
// for a program copied elsewhere), and returns the address of its exported
// `symbol`. Never closed. Throws dynsub::Error naming the library and what it
// is for (`purpose`) when it cannot be opened or is not DynSub's.
void* openOwnLibrary(const std::string& name, const std::string& buildPath, const char* symbol,
                     const std::string& purpose);

// The table of functions a library exports through `symbol`, a function
// taking nothing and returning `const Table*`: opens the library
// (openOwnLibrary) and calls it. Callers keep the result in a function-local
// static, so that the library is opened once, at the first call, thread-safely.
template <class Table>
const Table& ownLibraryTable(const std::string& name, const std::string& buildPath, const char* symbol,
                             const std::string& purpose) {
  using Entry = const Table* (*)();
  return *reinterpret_cast<Entry>(openOwnLibrary(name, buildPath, symbol, purpose))();
}

}  // namespace dynsub
