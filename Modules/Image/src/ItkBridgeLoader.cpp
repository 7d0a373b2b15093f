// Opens libDynSubItkBridge.so (ItkBridge.h says why it is a library of its own).
#include "ItkBridge.h"

#include "dynsub/OwnLibrary.h"

namespace dynsub::itkbridge {

const Functions& functions() {
  // Never closed: ITK's factories and GDCM's dictionary live until exit.
  using Entry = const Functions* (*)();
  static const Functions* const loaded = reinterpret_cast<Entry>(
      openOwnLibrary(DYNSUB_ITK_BRIDGE_NAME, DYNSUB_ITK_BRIDGE_BUILD_PATH, kFunctionsSymbol,
                     "library that reads and filters images through ITK"))();
  return *loaded;
}

}  // namespace dynsub::itkbridge
