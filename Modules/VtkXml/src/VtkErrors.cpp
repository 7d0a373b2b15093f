#include "dynsub/VtkErrors.h"

#include <vtkAlgorithm.h>
#include <vtkCallbackCommand.h>
#include <vtkCommand.h>
#include <vtkExecutive.h>

namespace dynsub {

VtkErrors::VtkErrors() : command_(vtkSmartPointer<vtkCallbackCommand>::New()) {
  command_->SetClientData(this);
  command_->SetCallback([](vtkObject*, unsigned long, void* client, void* text) {
    auto* self = static_cast<VtkErrors*>(client);
    if (self->first_.empty() && text) self->first_ = static_cast<const char*>(text);
  });
}

VtkErrors::~VtkErrors() = default;

void VtkErrors::watch(vtkAlgorithm* algorithm) {
  algorithm->AddObserver(vtkCommand::ErrorEvent, command_);
  algorithm->GetExecutive()->AddObserver(vtkCommand::ErrorEvent, command_);
}

}  // namespace dynsub
