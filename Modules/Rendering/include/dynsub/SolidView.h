#pragma once
// The 3D view of a sculpted solid (Sculpting.h): the solid's boundary surface
// (the boundary faces of its subdivided lattice, where the mass points are,
// smoothly shaded in a clay colour), the control lattice as a wireframe with
// its points (free ones white, fixed ones red), the rope as a green line from
// its mass point to its free end, and a selected control face highlighted
// (cyan). Units mm.
#include <memory>

#include <vtkSmartPointer.h>

#include "dynsub/Types.h"

class vtkActor;
class vtkRenderWindow;
class vtkRenderer;

namespace dynsub {

class Sculpture;

class SolidView {
 public:
  SolidView();
  ~SolidView();
  SolidView(const SolidView&) = delete;
  SolidView& operator=(const SolidView&) = delete;

  vtkRenderer* renderer() const;
  // The actor of the boundary surface (for picking).
  vtkActor* surfaceActor() const;

  // Draws the sculpture as it is now; `selectedFace` is a control face or -1.
  void show(const Sculpture& sculpture, int selectedFace = -1);
  void showControlLattice(bool visible);
  bool controlLatticeShown() const;

  // The control face a cell of the drawn surface lies in (-1 if none).
  int controlFaceOf(vtkIdType surfaceCell) const;

  // Looks at the solid from the front, right and above, all of it in view.
  void resetCamera();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// The figure `dynsub solid sculpt` writes (sculpted.png): the solid, its
// control lattice and fixed points as SolidView draws them; 800 x 800,
// off screen. Needs an X display (Figures.h).
vtkSmartPointer<vtkRenderWindow> sculptureFigure(const Sculpture& sculpture);
// sculptureFigure written as PNG (Figures.h's writePng).
void writeSculptureFigure(const Sculpture& sculpture, const std::string& path);

}  // namespace dynsub
