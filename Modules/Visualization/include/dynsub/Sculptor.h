#pragma once
// The sculpting window (`dynsub solid sculpt LATTICE`): a solid of virtual
// clay (Sculpting.h) that moves all the time, drawn by SolidView, and the
// paper's tools (§5.4) on the mouse and keys.
//
// Bindings (also on screen behind `h`):
//   left drag            rotate the view;  wheel: zoom
//   Ctrl + left drag     rope: grab the solid where clicked and pull
//   Shift + left click   select the control face under the cursor (cyan)
//   e                    extrude the selected face into a new cell
//   d, Delete            delete the selected face's cell
//   f / u                fix / unfix the selected face's control points
//   U                    unfix all
//   right click on a control point (within 8 px)   fix it, or unfix a fixed one
//   p                    plasticity: the current shape becomes the rest shape
//   k / K                stiffness down / up (x 0.8, x 1.25)
//   g / G                damping down / up (x 0.8, x 1.25)
//   space                pause or resume the motion
//   w                    show or hide the control lattice;  c  reset the view
//   s                    save (through the save action given)
//   h                    help;  q, Escape  quit
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
