#pragma once
// VTK reports a failure (a file it cannot read or write) as error events of
// the object and of its pipeline's executive, printed to stderr when nobody
// listens. A VtkErrors listens instead and keeps the first message, for an
// error that names the file.
#include <string>

#include <vtkSmartPointer.h>

class vtkAlgorithm;
class vtkCallbackCommand;

namespace dynsub {

class VtkErrors {
 public:
  VtkErrors();
  ~VtkErrors();
  VtkErrors(const VtkErrors&) = delete;
  VtkErrors& operator=(const VtkErrors&) = delete;

  // Listens to `algorithm`'s error events and to its executive's.
  void watch(vtkAlgorithm* algorithm);
  // The first message heard, "" when none; VTK's source location and the
  // object's class and address come first in it.
  const std::string& first() const { return first_; }

 private:
  std::string first_;
  vtkSmartPointer<vtkCallbackCommand> command_;
};

}  // namespace dynsub
