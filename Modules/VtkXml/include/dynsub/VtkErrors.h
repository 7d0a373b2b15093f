#pragma once
// VTK reports a failure (a file it cannot read or write) as error events of
// the object and of its pipeline's executive, printed to stderr when nobody
// listens. A VtkErrors listens instead and keeps the first message, for an
// error that names the file. While one lives (on any thread), VTK's log
// prints nothing to stderr: the objects inside a reader (its XML parser),
// which it cannot listen to, would print their own part of the failure it
// reports.
#include <string>
#include <utility>
#include <vector>

#include <vtkSmartPointer.h>
#include <vtkWeakPointer.h>

class vtkAlgorithm;
class vtkCallbackCommand;
class vtkObject;

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
  // The first message's reason alone, for a person: without VTK's "ERROR:
  // In FILE, line N" and "vtkClass (0x...): " ("Error parsing XML in stream
  // at line 389, column 91, byte index 47334: no element found").
  std::string reason() const;

 private:
  std::string first_;
  vtkSmartPointer<vtkCallbackCommand> command_;
  // What it listens to, with the observers' tags, removed on destruction.
  std::vector<std::pair<vtkWeakPointer<vtkObject>, unsigned long>> watched_;
};

}  // namespace dynsub
