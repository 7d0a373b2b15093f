#pragma once
// Driving an interactor with recorded events (vtkInteractorEventRecorder's
// stream format, version 1.1): "Event x y modifiers keycode repeat keysym",
// modifiers a sum of Shift 1, Ctrl 2, Alt 4. Header-only, for the tests.
#include <cmath>
#include <sstream>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <vtkInteractorEventRecorder.h>
#include <vtkNew.h>
#include <vtkRenderWindowInteractor.h>

namespace dynsub::events {

constexpr int kShift = 1;
constexpr int kCtrl = 2;

// Plays the lines, in order, into `interactor`.
inline void play(vtkRenderWindowInteractor* interactor, const std::vector<std::string>& lines) {
  std::ostringstream stream;
  stream << "# StreamVersion 1.1\n";
  for (const std::string& line : lines) stream << line << '\n';
  vtkNew<vtkInteractorEventRecorder> recorder;
  recorder->SetInteractor(interactor);
  recorder->ReadFromInputStringOn();
  const std::string text = stream.str();
  recorder->SetInputString(text.c_str());
  recorder->Play();
  recorder->Off();
}

// A mouse event at a display position.
inline std::string mouse(const char* event, const Eigen::Vector2d& at, int modifiers = 0) {
  std::ostringstream line;
  line << event << ' ' << std::lround(at.x()) << ' ' << std::lround(at.y()) << ' ' << modifiers << " 0 0 0";
  return line.str();
}

// A key press at a display position: its key symbol and character.
inline std::string key(const char* keySym, char code, const Eigen::Vector2d& at = Eigen::Vector2d(10, 10)) {
  std::ostringstream line;
  line << "KeyPressEvent " << std::lround(at.x()) << ' ' << std::lround(at.y()) << " 0 " << int(code) << " 1 "
       << keySym;
  return line.str();
}

}  // namespace dynsub::events
