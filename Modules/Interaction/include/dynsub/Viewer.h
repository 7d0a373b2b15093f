#pragma once
// The interactive viewer (`dynsub view`): axial, coronal and sagittal slice
// views and a 3D view of one image, its landmarks and a surface, with live
// fitting by the segmentation pipeline (Segmentation.h).
//
// Bindings: the on-screen help behind `h` (kHelp in Viewer.cpp) is their one
// list. In short: clicks on a slice place, select, move and delete
// landmarks (saved in place of the file's points, updateLandmarks); Ctrl +
// drag on the 3D surface pulls it with an interactive spring; space starts,
// pauses and resumes fitting.
// Fitting runs on a worker thread: the first fit starts from the landmarks'
// initial model (at least 4 landmarks), and the surface is redrawn in every
// view as it moves (about 25 times a second). Editing the landmarks while
// fitting, or after a fit, refits: from the last finished fit if there is one
// (its control mesh and level), reusing its region and edge field (with
// the edge thresholds the region was built with) while the landmarks and the
// surface stay inside; otherwise from the initial model. The status line
// gives each fit's steps and time.
#include <memory>
#include <string>
#include <vector>

#include <vtkSmartPointer.h>

#include "dynsub/SlicePlanes.h"
#include "dynsub/ViewerInput.h"

class vtkPolyData;
class vtkRenderWindow;
class vtkRenderWindowInteractor;
class vtkRenderer;

namespace dynsub {

class SliceView;
class ViewerStyle;


class Viewer {
 public:
  // Builds the window (1200 x 900) and its interactor; needs an X display.
  explicit Viewer(ViewerInput input);
  ~Viewer();
  Viewer(const Viewer&) = delete;
  Viewer& operator=(const Viewer&) = delete;

  vtkRenderWindow* window() const;
  vtkRenderWindowInteractor* interactor() const;
  // Shows the window and runs the event loop until it closes.
  void run();

  // What the bindings do, for scripts and tests.
  SliceView& sliceView(SliceOrientation orientation) const;
  vtkRenderer* surfaceRenderer() const;
  const std::vector<Landmark>& landmarks() const;
  void saveLandmarks();
  void loadLandmarks();
  void startOrPauseFitting();
  void resetFitting();
  bool fitting() const;  // a fit or refit is running or paused
  // Processes live updates (and renders) until the fit ends or `seconds`
  // pass; true if it ended. For tests and scripts without an event loop.
  bool waitForFit(double seconds);
  int surfaceUpdates() const;  // times the live surface was redrawn
  std::string status() const;  // the status line shown in the window

 private:
  friend class ViewerStyle;  // the interactor style acts on the viewer's state
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace dynsub
