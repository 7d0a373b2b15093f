#include "dynsub/VtkErrors.h"

#include <vtkAlgorithm.h>
#include <vtkCallbackCommand.h>
#include <vtkCommand.h>
#include <vtkExecutive.h>
#include <vtkLogger.h>

#include <sstream>

namespace dynsub {

VtkErrors::VtkErrors()
    : command_(vtkSmartPointer<vtkCallbackCommand>::New()), stderrVerbosity_(vtkLogger::GetCurrentVerbosityCutoff()) {
  vtkLogger::SetStderrVerbosity(vtkLogger::VERBOSITY_OFF);
  command_->SetClientData(this);
  command_->SetCallback([](vtkObject*, unsigned long, void* client, void* text) {
    auto* self = static_cast<VtkErrors*>(client);
    if (self->first_.empty() && text) self->first_ = static_cast<const char*>(text);
  });
}

VtkErrors::~VtkErrors() {
  vtkLogger::SetStderrVerbosity(static_cast<vtkLogger::Verbosity>(stderrVerbosity_));
}

std::string VtkErrors::reason() const {
  std::istringstream lines(first_);
  for (std::string line; std::getline(lines, line);) {
    if (line.empty() || line.rfind("ERROR: In ", 0) == 0 || line.rfind("Warning: In ", 0) == 0) continue;
    // "vtkXMLDataParser (0x55bb834416e0): Error parsing ..." -> "Error parsing ..."
    const auto address = line.find(" (0x");
    const auto end = address == std::string::npos ? std::string::npos : line.find("): ", address);
    if (line.rfind("vtk", 0) == 0 && end != std::string::npos) line = line.substr(end + 3);
    while (!line.empty() && (line.back() == ' ' || line.back() == '\r')) line.pop_back();
    if (!line.empty()) return line;
  }
  return first_;
}

void VtkErrors::watch(vtkAlgorithm* algorithm) {
  algorithm->AddObserver(vtkCommand::ErrorEvent, command_);
  algorithm->GetExecutive()->AddObserver(vtkCommand::ErrorEvent, command_);
}

}  // namespace dynsub
