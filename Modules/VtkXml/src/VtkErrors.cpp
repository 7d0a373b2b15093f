#include "dynsub/VtkErrors.h"

#include <vtkAlgorithm.h>
#include <vtkCallbackCommand.h>
#include <vtkCommand.h>
#include <vtkExecutive.h>
#include <vtkLogger.h>

#include <mutex>
#include <sstream>

#include "dynsub/TextFields.h"

namespace dynsub {

namespace {

// The VtkErrors alive, and the stderr verbosity the first found (DynSub
// logs to no file, so VTK's cutoff is stderr's), given back by the last.
std::mutex quietMutex;
int quietCount = 0;
vtkLogger::Verbosity quietSaved = vtkLogger::VERBOSITY_OFF;

}  // namespace

VtkErrors::VtkErrors() : command_(vtkSmartPointer<vtkCallbackCommand>::New()) {
  {
    const std::lock_guard<std::mutex> lock(quietMutex);
    if (quietCount++ == 0) {
      quietSaved = vtkLogger::GetCurrentVerbosityCutoff();
      vtkLogger::SetStderrVerbosity(vtkLogger::VERBOSITY_OFF);
    }
  }
  command_->SetClientData(this);
  command_->SetCallback([](vtkObject*, unsigned long, void* client, void* text) {
    auto* self = static_cast<VtkErrors*>(client);
    if (self->first_.empty() && text) self->first_ = static_cast<const char*>(text);
  });
}

VtkErrors::~VtkErrors() {
  for (const auto& [object, tag] : watched_)
    if (object) object->RemoveObserver(tag);
  const std::lock_guard<std::mutex> lock(quietMutex);
  if (--quietCount == 0) vtkLogger::SetStderrVerbosity(quietSaved);
}

std::string VtkErrors::reason() const {
  std::istringstream lines(first_);
  for (std::string line; std::getline(lines, line);) {
    if (line.empty() || line.rfind("ERROR: In ", 0) == 0 || line.rfind("Warning: In ", 0) == 0) continue;
    line = afterObjectAddress(line);  // "vtkXMLDataParser (0x55...): Error parsing ..."
    while (!line.empty() && (line.back() == ' ' || line.back() == '\r')) line.pop_back();
    if (!line.empty()) return line;
  }
  return first_;
}

void VtkErrors::watch(vtkAlgorithm* algorithm) {
  watched_.emplace_back(algorithm, algorithm->AddObserver(vtkCommand::ErrorEvent, command_));
  vtkExecutive* executive = algorithm->GetExecutive();
  watched_.emplace_back(executive, executive->AddObserver(vtkCommand::ErrorEvent, command_));
}

}  // namespace dynsub
