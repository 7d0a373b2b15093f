#include "dynsub/VtkXmlWriter.h"

#include <vtkCallbackCommand.h>
#include <vtkCommand.h>
#include <vtkExecutive.h>
#include <vtkNew.h>
#include <vtkPolyData.h>
#include <vtkSmartPointer.h>
#include <vtkUnstructuredGrid.h>
#include <vtkXMLPolyDataWriter.h>
#include <vtkXMLUnstructuredGridWriter.h>

#include "dynsub/AtomicOutput.h"
#include "dynsub/Error.h"

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
  // VTK reports a failed write (a full disk, a closed stream) as error events
  // of the writer and of its pipeline's executive; the first is kept for the
  // exception instead of going to stderr unnamed.
  std::string message;
  vtkNew<vtkCallbackCommand> onError;
  onError->SetClientData(&message);
  onError->SetCallback([](vtkObject*, unsigned long, void* client, void* text) {
    auto* kept = static_cast<std::string*>(client);
    if (kept->empty() && text) *kept = static_cast<const char*>(text);
  });
  writer->AddObserver(vtkCommand::ErrorEvent, onError);
  writer->GetExecutive()->AddObserver(vtkCommand::ErrorEvent, onError);
  writer->SetInputData(data);
  writer->SetFileName(path.c_str());
  writer->SetDataModeToAppended();
  writer->EncodeAppendedDataOff();
  writer->SetCompressorTypeToLZ4();
  if (writer->Write() != 1 || writer->GetErrorCode() != 0) {
    // VTK's message starts with its source file and line, then the class and
    // address: the reason is what follows them.
    const std::size_t reason = message.rfind("): ");
    if (reason != std::string::npos) message.erase(0, reason + 3);
    while (!message.empty() && (message.back() == '\n' || message.back() == ' ')) message.pop_back();
    throw writeFailure(name, withoutTemporaryPrefix(message));
  }
}

}  // namespace dynsub
