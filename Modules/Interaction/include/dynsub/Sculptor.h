#pragma once
// The sculpting window (`dynsub solid sculpt LATTICE`): a solid of virtual
// clay (Sculpting.h) that moves all the time, drawn by SolidView, and the
// paper's tools (§5.4) on the mouse and keys.
//
// Bindings: the on-screen help behind `h` (kHelp in Sculptor.cpp) is their
// one list: the rope (Ctrl + drag), selecting a control face (Shift +
// click), extruding and deleting cells, fixing control points, plasticity,
// stiffness and damping (each step x 0.8 or x 1.25), pausing, saving.
// The solid moves in real time: every 40 ms the simulation advances by as
// many time steps as fit in 40 ms of simulated time.
#include <functional>
#include <memory>
#include <string>

#include "dynsub/Sculpting.h"

class vtkRenderWindow;
class vtkRenderWindowInteractor;

namespace dynsub {

class SolidView;
class SculptorStyle;

class Sculptor {
 public:
  // `save` is what `s` does with the sculpture: it returns a message for the
  // status line or throws. Builds the window (1000 x 800); needs an X display.
  Sculptor(const Lattice& control, const SculptSettings& settings,
           std::function<std::string(const Sculpture&)> save);
  ~Sculptor();
  Sculptor(const Sculptor&) = delete;
  Sculptor& operator=(const Sculptor&) = delete;

  vtkRenderWindow* window() const;
  vtkRenderWindowInteractor* interactor() const;
  // Shows the window and runs the event loop until it closes.
  void run();

  // For tests and scripts without an event loop.
  const Sculpture& sculpture() const;
  SolidView& view() const;
  int selectedFace() const;
  bool paused() const;
  // `ticks` simulation updates of 40 ms each, each followed by a render.
  void advance(int ticks);
  std::string status() const;  // the status line shown in the window

 private:
  friend class SculptorStyle;  // the interactor style acts on the sculptor's state
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace dynsub
