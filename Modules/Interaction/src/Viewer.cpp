#include "dynsub/Viewer.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <iomanip>
#include <memory>
#include <optional>
#include <sstream>

#include <vtkActor.h>
#include <vtkCallbackCommand.h>
#include <vtkCamera.h>
#include <vtkCellPicker.h>
#include <vtkInteractorStyleTrackballCamera.h>
#include <vtkNew.h>
#include <vtkMapper.h>
#include <vtkObjectFactory.h>
#include <vtkPolyData.h>
#include <vtkPropCollection.h>
#include <vtkRenderWindow.h>
#include <vtkRenderWindowInteractor.h>
#include <vtkRenderer.h>
#include <vtkTextActor.h>
#include <vtkTextProperty.h>

#include "FitWorker.h"
#include "dynsub/SceneStyle.h"
#include "dynsub/Error.h"
#include "dynsub/Figures.h"
#include "dynsub/SliceView.h"
#include "dynsub/TextFields.h"
#include "dynsub/SurfacePolyData.h"
#include "dynsub/SurfaceView.h"
#include "dynsub/Tessellation.h"

namespace dynsub {

namespace {

constexpr double kPickPixels = 8.0;  // how near a click must be to a landmark

const char* const kHelp =
    "Slice views:  wheel, Up/Down, Page Up/Down  next / previous slice\n"
    "              + / -  zoom in / out\n"
    "              left click  place a landmark (on one: select it); drag to move it\n"
    "              right click on a landmark, Delete, BackSpace  delete it\n"
    "3D view:      left drag  rotate;  wheel  zoom\n"
    "              Ctrl + left drag on the surface  pull it (after a fit: refit with the pull)\n"
    "Keys:         space  start (after a fit: refit) / pause / resume;  r  stop and forget the fit\n"
    "              s  save landmarks;  l  load landmarks;  h  this help;  q, Escape  quit";

}  // namespace

// The landmarks being edited: the list, the selection and the drag.
struct LandmarkEdits {
  std::vector<Landmark> landmarks;
  int selected = -1;
  int dragView = -1;    // slice view a landmark is being dragged in
  bool moved = false;   // the dragged landmark moved

  // A placed landmark's name takes a number no landmark of the file or of
  // this session has had, so that saving never gives it the file entry
  // (id, description) of one deleted (updateLandmarks matches by name).
  void add(const Vector3& p) {
    landmarks.push_back({"P-" + std::to_string(nextNumber++), p});
    selected = static_cast<int>(landmarks.size()) - 1;
  }
  void replace(std::vector<Landmark> loaded) {
    landmarks = std::move(loaded);
    nextNumber = std::max(nextNumber, numberAfter(landmarks));
  }
  int nextNumber = 1;

  // One past the largest n of the names "P-n" and "F-n" among `marks`.
  static int numberAfter(const std::vector<Landmark>& marks) {
    int after = 1;
    for (const Landmark& l : marks) {
      if (l.label.size() < 3 || (l.label[0] != 'P' && l.label[0] != 'F') || l.label[1] != '-') continue;
      const std::string digits = l.label.substr(2);
      if (digits.size() > 6 || !std::all_of(digits.begin(), digits.end(), [](char c) { return c >= '0' && c <= '9'; }))
        continue;
      after = std::max(after, std::stoi(digits) + 1);
    }
    return after;
  }
};

struct Viewer::Impl {
  ViewerInput input;
  vtkSmartPointer<vtkPolyData> startSurface;  // input.surfacePath's, or null
  // The scene.
  ImageSlices slices;
  std::unique_ptr<SliceView> views[3];
  SurfaceView surface3d;
  vtkNew<vtkRenderWindow> window;
  vtkNew<vtkRenderWindowInteractor> interactor;
  vtkNew<vtkRenderer> overlay;
  vtkNew<vtkTextActor> helpText;
  vtkNew<vtkTextActor> statusText;
  vtkNew<vtkPolyData> liveSurface;
  vtkNew<vtkCallbackCommand> timerCommand;
  vtkNew<vtkCellPicker> picker;
  int updates = 0;  // times liveSurface took a new surface
  // Whether the fit ran at the last redraw: the one after it ends shows how
  // it ended (done, or why it failed).
  bool fitWasRunning = false;

  LandmarkEdits edits;
  // The pull as the hand holds it.
  bool pulling = false;
  double pullDepth = 0;                    // display depth of the grabbed point
  Vector3 grabbedPoint = Vector3::Zero();  // where the pull took hold of the surface
  std::string message;                     // the last action's outcome

  FitWorker fit;

  explicit Impl(ViewerInput in);
  ~Impl() { fit.stop(); }

  int viewAt(int x, int y) {
    vtkRenderer* poked = interactor->FindPokedRenderer(x, y);
    for (int v = 0; v < 3; ++v)
      if (views[v]->renderer() == poked) return v;
    return surface3d.renderer() == poked ? 3 : -1;
  }

  int landmarkNear(int view, double x, double y) {
    int best = -1;
    double nearest = kPickPixels;
    for (int i : views[view]->landmarksOnSlice()) {
      const double d = (views[view]->displayPosition(edits.landmarks[i].position) - Eigen::Vector2d(x, y)).norm();
      if (d <= nearest) {
        nearest = d;
        best = i;
      }
    }
    return best;
  }

  void showLandmarks() {
    const MatrixX3 points = landmarkPositions(edits.landmarks);
    for (auto& v : views) v->setLandmarks(points, edits.selected);
    surface3d.setLandmarks(points, edits.selected);
  }

  void showSlices() {
    surface3d.showSlices(views[0]->sliceIndex(), views[1]->sliceIndex(), views[2]->sliceIndex());
  }

  void landmarksChanged() {
    showLandmarks();
    if (fit.running() || fit.hasFit()) {
      const bool refit = fit.hasFit();  // read before a new worker may write it
      startFit();  // the fit restarts with the new set, from the last fit if there is one
      if (fit.running()) message = refit ? "landmarks changed: refitting" : "landmarks changed: fitting again";
    }
  }

  // A click on slice view `view`: select the landmark there, or place one.
  void clickSlice(int view, int x, int y) {
    const int hit = landmarkNear(view, x, y);
    if (hit < 0) {
      // The margin around a slice is no place in the image: segment would
      // refuse such a landmark.
      const Vector3 point = views[view]->pointAt(x, y);
      if (!slices.geometry().covers(point)) {
        message = "outside the image: no landmark placed";
        showLandmarks();
        return;
      }
      edits.add(point);
      message = "placed " + edits.landmarks.back().label;
      edits.moved = true;
    } else {
      edits.selected = hit;
      message = "selected " + edits.landmarks[hit].label;
    }
    edits.dragView = view;
    showLandmarks();
  }

  void dragLandmarkTo(int x, int y) {
    const Vector3 point = views[edits.dragView]->pointAt(x, y);
    if (!slices.geometry().covers(point)) return;  // it stays where it last lay in the image
    edits.landmarks[edits.selected].position = point;
    edits.moved = true;
    showLandmarks();
  }

  void endDrag() {
    edits.dragView = -1;
    if (edits.moved) {
      edits.moved = false;
      landmarksChanged();
    }
  }

  void deleteLandmark(int i) {
    if (i < 0 || i >= static_cast<int>(edits.landmarks.size())) return;
    message = "deleted " + edits.landmarks[i].label;
    edits.landmarks.erase(edits.landmarks.begin() + i);
    edits.selected = -1;
    landmarksChanged();
  }

  void stepSlice(int view, int delta) {
    if (view < 0 || view > 2) return;
    views[view]->showSlice(views[view]->sliceIndex() + delta);
    showSlices();
  }

  void zoom(int view, double factor) {
    if (view < 0 || view > 3) return;
    vtkRenderer* r = view == 3 ? surface3d.renderer() : views[view]->renderer();
    r->GetActiveCamera()->Zoom(factor);
  }

  void save() {
    try {
      updateLandmarks(edits.landmarks, input.landmarksPath);
      message = "saved " + std::to_string(edits.landmarks.size()) + " landmarks to " + input.landmarksPath;
    } catch (const std::exception& e) {
      message = std::string("not saved: ") + e.what();
    }
  }

  void load() {
    try {
      edits.replace(readLandmarks(input.landmarksPath));
      edits.selected = -1;
      message = "loaded " + std::to_string(edits.landmarks.size()) + " landmarks from " + input.landmarksPath;
      landmarksChanged();
    } catch (const std::exception& e) {
      message = std::string("not loaded: ") + e.what();
    }
  }

  void stopFit() {
    fit.stop();  // lets go of the pull
    pulling = false;
  }

  void startFit() {
    stopFit();
    launchFit();
  }

  // A fit of the landmarks as they are now, when there are enough.
  void launchFit() {
    if (edits.landmarks.size() < 4) {
      message = "place at least 4 landmarks to fit (" + std::to_string(edits.landmarks.size()) + " so far)";
      return;
    }
    fit.start(edits.landmarks);
  }

  // Ctrl + click on the 3D view: take hold of the surface under the cursor.
  void grabSurface(int x, int y) {
    if (!fit.running() && !fit.hasFit()) {
      message = "start fitting (space) to pull the surface";
      return;
    }
    if (!picker->Pick(x, y, 0, surface3d.renderer()) || liveSurface->GetNumberOfPoints() == 0) return;
    double p[3];
    picker->GetPickPosition(p);
    grabbedPoint = Vector3(p[0], p[1], p[2]);
    pullDepth = style::displayAt(surface3d.renderer(), grabbedPoint).z();
    // After a fit, the pull refits from it.
    pullTo(grabbedPoint, true);
    message = "pulling";
  }

  // The hand moved to (x, y) at the grabbed point's depth.
  void movePull(int x, int y) {
    // A refit may have settled before the hand moved on (it takes tens of
    // milliseconds): then another starts from where it settled.
    pullTo(style::worldAt(surface3d.renderer(), x, y, pullDepth), false);
  }

  void releasePull() {
    fit.release();
    pulling = false;
    message = "released";
  }

  // The pull, held at grabbedPoint, drawn to `target`; `grab`: it takes hold
  // anew. A running fit takes it (FitWorker::pullRunningFit). Otherwise a
  // refit starts with the pull on from its first step (held before the worker
  // starts, or a refit that settled at once would never see it).
  void pullTo(const Vector3& target, bool grab) {
    if (fit.pullRunningFit(grabbedPoint, target, grab)) {
      pulling = true;
      return;
    }
    stopFit();  // lets go of the pull
    fit.grab(grabbedPoint, target);
    pulling = true;
    launchFit();
  }

  // On the interface thread: take what the fit published.
  bool takeUpdate() {
    std::optional<TriangleSurface> surface = fit.take();
    if (!surface) return false;
    liveSurface->ShallowCopy(toPolyData(*surface));
    liveSurface->Modified();
    ++updates;
    return true;
  }

  void updateStatus() {
    std::ostringstream text;
    const std::string fitting = fit.status();
    text << edits.landmarks.size() << " landmarks  |  " << (fitting.empty() ? "not fitting (space starts)" : fitting);
    // The status has the window's right half: a message naming a long path
    // breaks into lines instead of running off the window.
    if (!message.empty()) text << "\n" << wrapped(message, style::textColumns(0.48 * window->GetSize()[0], 13));
    statusText->SetInput(text.str().c_str());
  }

  void render() {
    updateStatus();
    window->Render();
  }

  void togglePause() {
    if (!fit.running()) {
      startFit();
      return;
    }
    fit.togglePause();
  }

  void reset() {
    fit.forget();
    pulling = false;
    if (startSurface) {
      liveSurface->ShallowCopy(startSurface);
    } else {
      liveSurface->Initialize();
    }
    liveSurface->Modified();
    message = "reset";
  }
};

// Routes the mouse and keys to the viewer's actions; the 3D view keeps the trackball.
class ViewerStyle : public vtkInteractorStyleTrackballCamera {
 public:
  static ViewerStyle* New();
  vtkTypeMacro(ViewerStyle, vtkInteractorStyleTrackballCamera);
  Viewer::Impl* viewer = nullptr;

  void OnLeftButtonDown() override {
    int x, y;
    Interactor->GetEventPosition(x, y);
    const int view = viewer->viewAt(x, y);
    if (view >= 0 && view < 3) {
      viewer->clickSlice(view, x, y);
      viewer->render();
      return;
    }
    if (view == 3 && Interactor->GetControlKey()) {
      viewer->grabSurface(x, y);
      viewer->render();
      return;
    }
    vtkInteractorStyleTrackballCamera::OnLeftButtonDown();
  }

  void OnMouseMove() override {
    int x, y;
    Interactor->GetEventPosition(x, y);
    if (viewer->edits.dragView >= 0 && viewer->edits.selected >= 0) {
      viewer->dragLandmarkTo(x, y);
      viewer->render();
      return;
    }
    if (viewer->pulling) {
      viewer->movePull(x, y);
      return;
    }
    vtkInteractorStyleTrackballCamera::OnMouseMove();
  }

  void OnLeftButtonUp() override {
    if (viewer->edits.dragView >= 0) {
      viewer->endDrag();
      viewer->render();
      return;
    }
    if (viewer->pulling) {
      viewer->releasePull();
      viewer->render();
      return;
    }
    vtkInteractorStyleTrackballCamera::OnLeftButtonUp();
  }

  void OnRightButtonDown() override {
    int x, y;
    Interactor->GetEventPosition(x, y);
    const int view = viewer->viewAt(x, y);
    if (view >= 0 && view < 3) {
      viewer->deleteLandmark(viewer->landmarkNear(view, x, y));
      viewer->render();
      return;
    }
    vtkInteractorStyleTrackballCamera::OnRightButtonDown();
  }

  void OnMouseWheelForward() override { wheel(+1); }
  void OnMouseWheelBackward() override { wheel(-1); }

  void wheel(int delta) {
    int x, y;
    Interactor->GetEventPosition(x, y);
    const int view = viewer->viewAt(x, y);
    if (view >= 0 && view < 3) {
      viewer->stepSlice(view, delta);
      viewer->render();
      return;
    }
    if (delta > 0) {
      vtkInteractorStyleTrackballCamera::OnMouseWheelForward();
    } else {
      vtkInteractorStyleTrackballCamera::OnMouseWheelBackward();
    }
  }

  void OnKeyPress() override {
    const std::string key = Interactor->GetKeySym() ? Interactor->GetKeySym() : "";
    int x, y;
    Interactor->GetEventPosition(x, y);
    const int view = viewer->viewAt(x, y);
    if (key == "Up" || key == "Prior") {
      viewer->stepSlice(view, +1);
    } else if (key == "Down" || key == "Next") {
      viewer->stepSlice(view, -1);
    } else if (key == "plus" || key == "equal" || key == "KP_Add") {
      viewer->zoom(view, 1.25);
    } else if (key == "minus" || key == "KP_Subtract") {
      viewer->zoom(view, 0.8);
    } else if (key == "Delete" || key == "BackSpace") {
      viewer->deleteLandmark(viewer->edits.selected);
    } else if (key == "space") {
      viewer->togglePause();
    } else if (key == "r") {
      viewer->reset();
    } else if (key == "s") {
      viewer->save();
    } else if (key == "l") {
      viewer->load();
    } else if (key == "h") {
      viewer->helpText->SetVisibility(!viewer->helpText->GetVisibility());
    } else if (key == "q" || key == "Escape") {
      viewer->stopFit();
      Interactor->ExitCallback();
      return;
    } else {
      return;
    }
    viewer->render();
  }

  // VTK's default single-key bindings (wireframe, stereo, ...) would act on
  // every prop; the viewer's own keys are handled in OnKeyPress.
  void OnChar() override {}
};

vtkStandardNewMacro(ViewerStyle);

Viewer::Impl::Impl(ViewerInput in)
    : input(std::move(in)), slices(input.image), fit(input.image, input.segment, input.initialFraction, input.pullStiffness) {
  edits.replace(input.landmarks);
  window->SetSize(1200, 900);
  window->SetMultiSamples(0);
  window->SetWindowName("DynSub");
  window->SetNumberOfLayers(2);
  interactor->SetRenderWindow(window);
  vtkNew<ViewerStyle> style;
  style->viewer = this;
  interactor->SetInteractorStyle(style);

  if (!input.surfacePath.empty()) startSurface = readSurfacePolyData(input.surfacePath);
  if (startSurface) liveSurface->ShallowCopy(startSurface);
  // Start at the landmarks' centre, else the surface's, else the image's.
  Vector3 centre = slices.geometry().toPhysical(
      0.5 * Vector3(slices.geometry().size[0] - 1, slices.geometry().size[1] - 1, slices.geometry().size[2] - 1));
  if (!edits.landmarks.empty()) {
    centre = landmarkPositions(edits.landmarks).colwise().mean().transpose();
  } else if (liveSurface->GetNumberOfPoints() > 0) {
    double b[6];
    liveSurface->GetBounds(b);
    centre = Vector3(0.5 * (b[0] + b[1]), 0.5 * (b[2] + b[3]), 0.5 * (b[4] + b[5]));
  }
  const Vector3 extent = slices.geometry().spacing.cwiseProduct(
      Vector3(slices.geometry().size[0], slices.geometry().size[1], slices.geometry().size[2]));
  const double viewports[4][4] = {{0, 0.5, 0.5, 1}, {0.5, 0.5, 1, 1}, {0, 0, 0.5, 0.5}, {0.5, 0, 1, 0.5}};
  for (int v = 0; v < 3; ++v) {
    views[v] = std::make_unique<SliceView>(static_cast<SliceOrientation>(v));
    views[v]->setImage(&slices);
    views[v]->setSurface(liveSurface);
    views[v]->showSlice(slices.sliceThrough(static_cast<SliceOrientation>(v), centre));
    views[v]->frame(centre, 0.5 * extent.maxCoeff());
    views[v]->renderer()->SetViewport(viewports[v]);
    window->AddRenderer(views[v]->renderer());
  }
  surface3d.setSurface(liveSurface);
  surface3d.setImage(&slices);
  surface3d.setOpacity(0.85);
  surface3d.renderer()->SetViewport(viewports[3]);
  window->AddRenderer(surface3d.renderer());
  showSlices();
  showLandmarks();
  if (edits.landmarks.size() >= 2) {
    // The structure the landmarks outline, with room around it.
    const MatrixX3 points = landmarkPositions(edits.landmarks);
    const Vector3 low = points.colwise().minCoeff().transpose(), high = points.colwise().maxCoeff().transpose();
    const Vector3 room = 0.25 * (high - low) + Vector3::Constant(5.0);
    surface3d.frame(low - room, high + room);
  } else {
    surface3d.resetCamera();
  }

  overlay->SetLayer(1);
  overlay->InteractiveOff();
  style::helpOverlay(overlay, helpText, kHelp, 0.51, 0.49);
  style::cornerText(statusText, 0.51, 0.01, style::Corner::BottomLeft, 13);
  statusText->GetTextProperty()->SetBackgroundColor(0, 0, 0);
  statusText->GetTextProperty()->SetBackgroundOpacity(0.6);
  overlay->AddActor2D(statusText);
  window->AddRenderer(overlay);
  message = "h: help";

  picker->SetTolerance(0.002);
  picker->PickFromListOn();
  // The 3D view's surface is the only prop to pick; found through its mapper input.
  vtkPropCollection* props = surface3d.renderer()->GetViewProps();
  props->InitTraversal();
  for (vtkProp* prop = props->GetNextProp(); prop; prop = props->GetNextProp()) {
    auto* actor = vtkActor::SafeDownCast(prop);
    if (actor && actor->GetMapper() && actor->GetMapper()->GetInput() == liveSurface.Get()) picker->AddPickList(actor);
  }

  style::observeTimer(
      interactor, timerCommand,
      [](void* client) {
        auto* self = static_cast<Viewer::Impl*>(client);
        const bool updated = self->takeUpdate(), running = self->fit.running();
        if (updated || running || self->fitWasRunning) self->render();
        self->fitWasRunning = running;
      },
      this);
  updateStatus();
}

Viewer::Viewer(ViewerInput input) {
  std::string why;
  if (!displayAvailable(&why)) throw Error("the viewer needs an X display: " + why);
  impl_ = std::make_unique<Impl>(std::move(input));
}

Viewer::~Viewer() = default;

vtkRenderWindow* Viewer::window() const { return impl_->window; }
vtkRenderWindowInteractor* Viewer::interactor() const { return impl_->interactor; }

void Viewer::run() {
  impl_->interactor->Initialize();
  impl_->interactor->CreateRepeatingTimer(static_cast<unsigned long>(kRedrawInterval.count()));
  impl_->render();
  impl_->interactor->Start();
  impl_->stopFit();
}

SliceView& Viewer::sliceView(SliceOrientation orientation) const { return *impl_->views[static_cast<int>(orientation)]; }
vtkRenderer* Viewer::surfaceRenderer() const { return impl_->surface3d.renderer(); }
const std::vector<Landmark>& Viewer::landmarks() const { return impl_->edits.landmarks; }
void Viewer::saveLandmarks() { impl_->save(); }
void Viewer::loadLandmarks() { impl_->load(); }
void Viewer::startOrPauseFitting() { impl_->togglePause(); }
void Viewer::resetFitting() { impl_->reset(); }
bool Viewer::fitting() const { return impl_->fit.running(); }
int Viewer::surfaceUpdates() const { return impl_->updates; }

bool Viewer::waitForFit(double seconds) {
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
  while (impl_->fit.running() && std::chrono::steady_clock::now() < end) {
    if (impl_->takeUpdate()) impl_->render();
    std::this_thread::sleep_for(kRedrawInterval / 2);
  }
  if (impl_->takeUpdate()) impl_->render();
  return !impl_->fit.running();
}

std::string Viewer::status() const {
  impl_->updateStatus();
  return impl_->statusText->GetInput() ? impl_->statusText->GetInput() : "";
}

}  // namespace dynsub
