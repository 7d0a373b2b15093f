// Opens libDynSubItkBridge.so and libDynSubItkDicom.so (ItkBridge.h says why
// they are libraries of their own).
#include "ItkBridge.h"

#include "dynsub/OwnLibrary.h"

namespace dynsub::itkbridge {

// Never closed: ITK's factories and GDCM's dictionary live until exit.
const Functions& functions() {
  static const Functions& loaded =
      ownLibraryTable<Functions>(DYNSUB_ITK_BRIDGE_NAME, DYNSUB_ITK_BRIDGE_BUILD_PATH, kFunctionsSymbol,
                                 "library that reads and filters images through ITK");
  return loaded;
}

const DicomFunctions& dicomFunctions() {
  static const DicomFunctions& loaded =
      ownLibraryTable<DicomFunctions>(DYNSUB_ITK_DICOM_NAME, DYNSUB_ITK_DICOM_BUILD_PATH, kDicomFunctionsSymbol,
                                      "library that reads DICOM through ITK and GDCM");
  return loaded;
}

}  // namespace dynsub::itkbridge
