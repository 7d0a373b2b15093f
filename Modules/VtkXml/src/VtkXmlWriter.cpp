#include "dynsub/VtkXmlWriter.h"

#include <vtkPolyData.h>
#include <vtkSmartPointer.h>
#include <vtkUnstructuredGrid.h>
#include <vtkXMLPolyDataWriter.h>
#include <vtkXMLUnstructuredGridWriter.h>

#include "dynsub/AtomicOutput.h"
#include "dynsub/Error.h"
#include "dynsub/VtkErrors.h"

namespace dynsub {

void writeVtkXml(vtkDataObject* data, const std::string& path, const std::string& name) {
  vtkSmartPointer<vtkXMLWriter> writer;
  if (vtkPolyData::SafeDownCast(data)) {
    writer = vtkSmartPointer<vtkXMLPolyDataWriter>::New();
  } else if (vtkUnstructuredGrid::SafeDownCast(data)) {
    writer = vtkSmartPointer<vtkXMLUnstructuredGridWriter>::New();
  } else {
    throw Error(name, "internal: no VTK XML writer for this data");
  }
  // A failed write (a full disk, a closed stream) is reported in the error.
  VtkErrors errors;
  errors.watch(writer);
  writer->SetInputData(data);
  writer->SetFileName(path.c_str());
  writer->SetDataModeToAppended();
  writer->EncodeAppendedDataOff();
  writer->SetCompressorTypeToLZ4();
  if (writer->Write() != 1 || writer->GetErrorCode() != 0) {
    throw writeFailure(name, withoutTemporaryPrefix(errors.reason()));
  }
}

}  // namespace dynsub
