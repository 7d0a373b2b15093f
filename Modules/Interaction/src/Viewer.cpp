#include "dynsub/Viewer.h"

#include <atomic>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <iomanip>
#include <memory>
#include <mutex>
#include <optional>
#include <sstream>
#include <thread>

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

#include "dynsub/SceneStyle.h"
#include "dynsub/Error.h"
#include "dynsub/Figures.h"
#include "dynsub/PullForce.h"
#include "dynsub/SliceView.h"
#include "dynsub/SurfacePolyData.h"
#include "dynsub/SurfaceView.h"
#include "dynsub/Tessellation.h"

namespace dynsub {

namespace {

constexpr double kPickPixels = 8.0;  // how near a click must be to a landmark
constexpr auto kRedrawInterval = std::chrono::milliseconds(40);

const char* const kHelp =
    "Slice views:  wheel, Up/Down, Page Up/Down  next / previous slice\n"
    "              + / -  zoom in / out\n"
    "              left click  place a landmark (on one: select it); drag to move it\n"
    "              right click on a landmark, Delete, BackSpace  delete it\n"
    "3D view:      left drag  rotate;  wheel  zoom\n"
    "              Ctrl + left drag on the surface  pull it (after a fit: refit with the pull)\n"
    "Keys:         space  start (after a fit: refit) / pause / resume;  r  stop and forget the fit\n"
    "              s  save landmarks;  l  load landmarks;  h  this help;  q, Escape  quit";

struct FitCancelled {};

}  // namespace

struct Viewer::Impl {
  ViewerInput input;
  vtkSmartPointer<vtkPolyData> startSurface;  // input.surfacePath's, or null
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

  std::vector<Landmark> landmarks;
  int selected = -1;
  int dragView = -1;          // slice view a landmark is being dragged in
  bool landmarksEdited = false;
  bool pulling = false;
  double pullDepth = 0;       // display depth of the grabbed point
  Vector3 grabbedPoint = Vector3::Zero();  // where the pull took hold of the surface
  std::string message;        // the last action's outcome

  // The fit and what it hands to the interface thread.
  PullForceModel pull;
  std::thread worker;
  std::atomic<bool> running{false};
  std::mutex mutex;
  std::condition_variable resume;
  bool paused = false, cancel = false;
  bool fresh = false;  // a new surface is waiting
  TriangleSurface published;
  std::string fitText;
  int updates = 0;
  // What the next fit starts from: the last finished fit (its mesh and
  // levels) and the region whose edge directions it used; a refit reuses the
  // region while the landmarks and the surface stay inside it. Written by the
  // worker, read only while no worker runs; r (reset) forgets them.
  struct Fitted {
    ControlMesh mesh;
    LevelOrigin origin;
  };
  std::optional<Fitted> fitted;
  std::unique_ptr<const SegmentationRegion> region;

  explicit Impl(ViewerInput in);
  ~Impl() { stopFit(); }

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
      const double d = (views[view]->displayPosition(landmarks[i].position) - Eigen::Vector2d(x, y)).norm();
      if (d <= nearest) {
        nearest = d;
        best = i;
      }
    }
    return best;
  }

  void showLandmarks() {
    const Matrix3X points = landmarkPositions(landmarks);
    for (auto& v : views) v->setLandmarks(points, selected);
    surface3d.setLandmarks(points, selected);
  }

  void showSlices() {
    surface3d.showSlices(views[0]->sliceIndex(), views[1]->sliceIndex(), views[2]->sliceIndex());
  }

  void landmarksChanged() {
    showLandmarks();
    if (running || fitted) {
      const bool refit = fitted.has_value();  // read before a new worker may write it
      startFit();  // the fit restarts with the new set, from the last fit if there is one
      if (running) message = refit ? "landmarks changed: refitting" : "landmarks changed: fitting again";
    }
  }

  void addLandmark(const Vector3& p) {
    int number = static_cast<int>(landmarks.size()) + 1;
    landmarks.push_back({"P-" + std::to_string(number), p});
    selected = static_cast<int>(landmarks.size()) - 1;
  }

  void deleteLandmark(int i) {
    if (i < 0 || i >= static_cast<int>(landmarks.size())) return;
    message = "deleted " + landmarks[i].label;
    landmarks.erase(landmarks.begin() + i);
    selected = -1;
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
      writeLandmarks(landmarks, input.landmarksPath, CoordinateSystem::LPS);
      message = "saved " + std::to_string(landmarks.size()) + " landmarks to " + input.landmarksPath;
    } catch (const std::exception& e) {
      message = std::string("not saved: ") + e.what();
    }
  }

  void load() {
    try {
      landmarks = readLandmarks(input.landmarksPath);
      selected = -1;
      message = "loaded " + std::to_string(landmarks.size()) + " landmarks from " + input.landmarksPath;
      landmarksChanged();
    } catch (const std::exception& e) {
      message = std::string("not loaded: ") + e.what();
    }
  }

  void startFit() {
    stopFit();
    launchFit();
  }

  // The pull, held at grabbedPoint, drawn to `target`; `grab`: it takes hold
  // anew. A running fit takes it, decided under the lock the end of fit()
  // takes, so the fit cannot end between the test and the move. Otherwise a
  // refit starts with the pull on from its first step (held before the worker
  // starts, or a refit that settled at once would never see it).
  void pullTo(const Vector3& target, bool grab) {
    {
      std::lock_guard<std::mutex> lock(mutex);
      if (running) {
        if (grab) {
          pull.grab(grabbedPoint, target);
        } else {
          pull.moveTo(target);
        }
        pulling = true;
        return;
      }
    }
    stopFit();  // lets go of the pull
    pull.grab(grabbedPoint, target);
    pulling = true;
    launchFit();
  }

  void launchFit() {
    if (landmarks.size() < 4) {
      message = "place at least 4 landmarks to fit (" + std::to_string(landmarks.size()) + " so far)";
      return;
    }
    {
      std::lock_guard<std::mutex> lock(mutex);
      cancel = false;
      paused = false;
      fitText = "fitting: starting";
    }
    running = true;
    worker = std::thread([this, marks = landmarks, start = fitted] { fit(marks, start); });
  }

  void stopFit() {
    {
      std::lock_guard<std::mutex> lock(mutex);
      cancel = true;
      paused = false;
    }
    resume.notify_all();
    if (worker.joinable()) worker.join();
    pull.release();
    pulling = false;
  }

  void publish(TriangleSurface surface, const std::string& text) {
    std::lock_guard<std::mutex> lock(mutex);
    published = std::move(surface);
    fresh = true;
    fitText = text;
  }

  // The worker thread: the segmentation pipeline with a live observer, from
  // the cube inside the landmarks or, for a refit, from the last fit.
  void fit(const std::vector<Landmark>& marks, const std::optional<Fitted>& start) {
    try {
      const auto started = std::chrono::steady_clock::now();
      const ControlMesh initial = start ? start->mesh : initialFromLandmarks(marks);
      if (!start || !region || !region->covers(landmarkPositions(marks)) || !region->covers(initial.points()))
        region = std::make_unique<const SegmentationRegion>(input.image, marks, initial, input.segment);
      auto last = std::chrono::steady_clock::now() - kRedrawInterval;
      auto observe = [&](const Progress& p) {
        {
          std::unique_lock<std::mutex> lock(mutex);
          resume.wait(lock, [&] { return !paused || cancel; });
          if (cancel) throw FitCancelled{};
        }
        const auto now = std::chrono::steady_clock::now();
        if (now - last < kRedrawInterval || !p.surface || !p.controlPoints) return;
        last = now;
        std::ostringstream text;
        text << (start ? "refitting" : "fitting") << ": level " << p.level << ", step " << p.step << std::scientific
             << std::setprecision(3) << ", energy " << p.energy << " N mm";
        publish(tessellate(*p.surface, *p.controlPoints, 4), text.str());
      };
      unsigned moves = pull.moves();
      SegmentResult result = evolveInRegion(*region, marks, initial, start ? start->origin : LevelOrigin{},
                                            input.segment, observe, {&pull});
      for (;;) {
        fitted = Fitted{result.mesh, result.origin};
        const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
        double worst = 0;
        for (double d : result.landmarkDistances) worst = std::max(worst, d);
        std::ostringstream text;
        text << (start ? "refit" : "fit") << " done: " << result.mesh.vertexCount() << " control vertices, "
             << result.levels.back().level << " refinement(s), " << result.steps << " steps in " << std::fixed
             << std::setprecision(2) << seconds << " s;\nfarthest landmark " << worst << " mm";
        publish(tessellate(LimitSurface(result.mesh), result.mesh.points(), kOutputSegments), text.str());
        {
          // The pull moved during the fit, perhaps after its last step (a fit
          // may settle on a step that read the new target before moving to
          // it, or the hand moved while this one was being published): go on
          // from where it settled until a fit has seen the pull stand still.
          // Decided under the lock the interface takes to move the pull, so
          // no move falls between this test and the end of the fit.
          std::lock_guard<std::mutex> lock(mutex);
          if (!pull.active() || pull.moves() == moves) {
            running = false;
            return;
          }
          moves = pull.moves();
        }
        result = evolveInRegion(*region, marks, result.mesh, result.origin, input.segment, observe, {&pull});
      }
    } catch (const FitCancelled&) {
      std::lock_guard<std::mutex> lock(mutex);
      fitText = "fitting stopped";
    } catch (const std::exception& e) {
      std::lock_guard<std::mutex> lock(mutex);
      fitText = std::string("fitting failed: ") + e.what();
    }
    running = false;
  }

  // On the interface thread: take what the worker published.
  bool takeUpdate() {
    std::lock_guard<std::mutex> lock(mutex);
    if (!fresh) return false;
    fresh = false;
    liveSurface->ShallowCopy(toPolyData(published));
    liveSurface->Modified();
    ++updates;
    return true;
  }

  void updateStatus() {
    std::ostringstream text;
    {
      std::lock_guard<std::mutex> lock(mutex);
      text << landmarks.size() << " landmarks  |  " << (fitText.empty() ? "not fitting (space starts)" : fitText);
      if (paused && running) text << " (paused)";
    }
    if (!message.empty()) text << "\n" << message;
    statusText->SetInput(text.str().c_str());
  }

  void render() {
    updateStatus();
    window->Render();
  }

  void togglePause() {
    if (!running) {
      startFit();
      return;
    }
    {
      std::lock_guard<std::mutex> lock(mutex);
      paused = !paused;
    }
    resume.notify_all();
  }

  void reset() {
    stopFit();
    fitted.reset();
    region.reset();
    {
      std::lock_guard<std::mutex> lock(mutex);
      fitText.clear();
      fresh = false;
    }
    if (startSurface) {
      liveSurface->ShallowCopy(startSurface);
    } else {
      liveSurface->Initialize();
    }
    liveSurface->Modified();
    message = "reset";
  }
};

// Routes the mouse and keys to the viewer; the 3D view keeps the trackball.
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
      int hit = viewer->landmarkNear(view, x, y);
      if (hit < 0) {
        viewer->addLandmark(viewer->views[view]->pointAt(x, y));
        viewer->message = "placed " + viewer->landmarks.back().label;
        viewer->landmarksEdited = true;
      } else {
        viewer->selected = hit;
        viewer->message = "selected " + viewer->landmarks[hit].label;
      }
      viewer->dragView = view;
      viewer->showLandmarks();
      viewer->render();
      return;
    }
    if (view == 3 && Interactor->GetControlKey()) {
      if (!viewer->running && !viewer->fitted) {
        viewer->message = "start fitting (space) to pull the surface";
        viewer->render();
        return;
      }
      if (viewer->picker->Pick(x, y, 0, viewer->surface3d.renderer()) && viewer->liveSurface->GetNumberOfPoints() > 0) {
        double p[3];
        viewer->picker->GetPickPosition(p);
        const Vector3 grabbed(p[0], p[1], p[2]);
        vtkRenderer* r = viewer->surface3d.renderer();
        r->SetWorldPoint(p[0], p[1], p[2], 1.0);
        r->WorldToDisplay();
        viewer->pullDepth = r->GetDisplayPoint()[2];
        viewer->grabbedPoint = grabbed;
        // After a fit, the pull refits from it.
        viewer->pullTo(grabbed, true);
        viewer->message = "pulling";
        viewer->render();
      }
      return;
    }
    vtkInteractorStyleTrackballCamera::OnLeftButtonDown();
  }

  void OnMouseMove() override {
    int x, y;
    Interactor->GetEventPosition(x, y);
    if (viewer->dragView >= 0 && viewer->selected >= 0) {
      viewer->landmarks[viewer->selected].position = viewer->views[viewer->dragView]->pointAt(x, y);
      viewer->landmarksEdited = true;
      viewer->showLandmarks();
      viewer->render();
      return;
    }
    if (viewer->pulling) {
      vtkRenderer* r = viewer->surface3d.renderer();
      r->SetDisplayPoint(x, y, viewer->pullDepth);
      r->DisplayToWorld();
      const double* w = r->GetWorldPoint();
      // A refit may have settled before the hand moved on (it takes tens of
      // milliseconds): then another starts from where it settled.
      viewer->pullTo(Vector3(w[0] / w[3], w[1] / w[3], w[2] / w[3]), false);
      return;
    }
    vtkInteractorStyleTrackballCamera::OnMouseMove();
  }

  void OnLeftButtonUp() override {
    if (viewer->dragView >= 0) {
      viewer->dragView = -1;
      if (viewer->landmarksEdited) {
        viewer->landmarksEdited = false;
        viewer->landmarksChanged();
      }
      viewer->render();
      return;
    }
    if (viewer->pulling) {
      viewer->pull.release();
      viewer->pulling = false;
      viewer->message = "released";
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
      viewer->deleteLandmark(viewer->selected);
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

Viewer::Impl::Impl(ViewerInput in) : input(std::move(in)), slices(input.image), pull(input.pullStiffness) {
  landmarks = input.landmarks;
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
  if (!landmarks.empty()) {
    centre = landmarkPositions(landmarks).colwise().mean().transpose();
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
  if (landmarks.size() >= 2) {
    // The structure the landmarks outline, with room around it.
    const Matrix3X points = landmarkPositions(landmarks);
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
        const bool updated = self->takeUpdate();
        if (updated || self->running) self->render();
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
const std::vector<Landmark>& Viewer::landmarks() const { return impl_->landmarks; }
void Viewer::saveLandmarks() { impl_->save(); }
void Viewer::loadLandmarks() { impl_->load(); }
void Viewer::startOrPauseFitting() { impl_->togglePause(); }
void Viewer::resetFitting() { impl_->reset(); }
bool Viewer::fitting() const { return impl_->running; }
int Viewer::surfaceUpdates() const { return impl_->updates; }

bool Viewer::waitForFit(double seconds) {
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
  while (impl_->running && std::chrono::steady_clock::now() < end) {
    if (impl_->takeUpdate()) impl_->render();
    std::this_thread::sleep_for(kRedrawInterval / 2);
  }
  if (impl_->takeUpdate()) impl_->render();
  return !impl_->running;
}

std::string Viewer::status() const {
  impl_->updateStatus();
  return impl_->statusText->GetInput() ? impl_->statusText->GetInput() : "";
}

}  // namespace dynsub
