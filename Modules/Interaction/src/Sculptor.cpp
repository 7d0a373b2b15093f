#include "dynsub/Sculptor.h"

#include <cmath>
#include <iomanip>
#include <sstream>

#include <vtkCallbackCommand.h>
#include <vtkCellPicker.h>
#include <vtkInteractorStyleTrackballCamera.h>
#include <vtkNew.h>
#include <vtkObjectFactory.h>
#include <vtkRenderWindow.h>
#include <vtkRenderWindowInteractor.h>
#include <vtkRenderer.h>
#include <vtkTextActor.h>
#include <vtkTextProperty.h>

#include "dynsub/SceneStyle.h"
#include "dynsub/Error.h"
#include "dynsub/Figures.h"
#include "dynsub/SolidView.h"
#include "dynsub/TextFields.h"

namespace dynsub {

namespace {

constexpr int kTickMilliseconds = 40;
constexpr double kPickPixels = 8.0;  // how near a right click must be to a control point

const char* const kHelp =
    "left drag  rotate;  wheel  zoom;  c  reset the view\n"
    "Ctrl + left drag on the solid  rope: pull it\n"
    "Shift + left click on the solid  select a control face\n"
    "e  extrude the selected face;  d, Delete  delete its cell\n"
    "f / u  fix / unfix its control points;  U  unfix all\n"
    "right click on a control point  fix / unfix it\n"
    "p  plasticity (keep the current shape)\n"
    "k / K  stiffness down / up;  g / G  damping down / up\n"
    "space  pause / resume;  w  control lattice on / off\n"
    "s  save;  h  this help;  q, Escape  quit";

}  // namespace

struct Sculptor::Impl {
  Sculpture sculpture;
  std::function<std::string(const Sculpture&)> save;
  SolidView view;
  vtkNew<vtkRenderWindow> window;
  vtkNew<vtkRenderWindowInteractor> interactor;
  vtkNew<vtkRenderer> overlay;
  vtkNew<vtkTextActor> helpText;
  vtkNew<vtkTextActor> statusText;
  vtkNew<vtkCallbackCommand> timerCommand;
  vtkNew<vtkCellPicker> picker;
  int selected = -1;  // control face
  bool paused = false;
  bool pulling = false;
  double pullDepth = 0;  // display depth of the grabbed point
  std::string message = "h: help";

  Impl(const Lattice& control, const SculptSettings& settings, std::function<std::string(const Sculpture&)> saveAction)
      : sculpture(control, settings), save(std::move(saveAction)) {}

  // Runs a tool; its errors (an interior face, the last cell, ...) become the message.
  template <typename Tool>
  void act(Tool tool) {
    try {
      tool();
    } catch (const std::exception& e) {
      message = e.what();
    }
    redraw();
  }

  void redraw() {
    view.show(sculpture, selected);
    updateStatus();
    window->Render();
  }

  void updateStatus() {
    const Lattice& control = sculpture.rest();
    const SolidMaterial& m = sculpture.settings().material;
    const std::size_t fixed = sculpture.model().fixedPoints().size();
    std::ostringstream text;
    text << control.cellCount() << " cells, " << control.pointCount() << " control points (" << fixed
         << " fixed)  |  t = " << std::fixed << std::setprecision(1)
         << sculpture.steps() * sculpture.settings().timeStep << " s" << (paused ? " (paused)" : "")
         << "  |  stiffness " << std::defaultfloat << std::setprecision(3) << m.springStiffness << " / " << m.virtualStiffness
         << " N/mm, damping " << m.damping << " N s/mm";
    if (selected >= 0) text << "  |  face " << selected << " selected";
    // A message naming a long path breaks into lines within the window.
    if (!message.empty()) text << "\n" << wrapped(message, style::textColumns(0.98 * window->GetSize()[0], 13));
    statusText->SetInput(text.str().c_str());
  }

  void tick() {
    if (paused) return;
    const int steps = std::max(1, static_cast<int>(std::lround(kTickMilliseconds / 1000.0 /
                                                                sculpture.settings().timeStep)));
    try {
      sculpture.run(steps);
    } catch (const std::exception& e) {
      paused = true;
      pulling = false;
      sculpture.release();
      message = std::string(e.what()) + " (paused: lower the stiffness, then press space)";
    }
    redraw();
  }

  // The solid's surface under a display position: the control face, and the point (mm).
  int pick(int x, int y, Vector3* at) {
    if (!picker->Pick(x, y, 0, view.renderer())) return -1;
    double p[3];
    picker->GetPickPosition(p);
    if (at) *at = Vector3(p[0], p[1], p[2]);
    return view.controlFaceOf(picker->GetCellId());
  }

  void grab(int x, int y) {
    Vector3 at;
    if (pick(x, y, &at) < 0) return;
    act([&] {
      sculpture.grab(at);
      pullDepth = style::displayAt(view.renderer(), at).z();
      pulling = true;
      message = "rope: pulling";
    });
  }

  void pullTo(int x, int y) {
    const Vector3 to = style::worldAt(view.renderer(), x, y, pullDepth);
    act([&] { sculpture.pullTo(to); });
  }

  void select(int x, int y) {
    selected = pick(x, y, nullptr);
    message = selected >= 0 ? "selected face " + std::to_string(selected) +
                                  (sculpture.rest().isBoundaryFace(selected) ? "" : " (inside)")
                            : "nothing selected";
    redraw();
  }

  bool requireSelection() {
    if (selected >= 0) return true;
    message = "select a face first (Shift + click on the solid)";
    redraw();
    return false;
  }

  void extrude() {
    if (!requireSelection()) return;
    act([&] {
      const int from = selected;
      selected = sculpture.extrude(from);
      pulling = false;
      message = "extruded face " + std::to_string(from) + " into cell " +
                std::to_string(sculpture.rest().cellCount() - 1) + " (e again continues from its end)";
    });
  }

  void deleteCell() {
    if (!requireSelection()) return;
    act([&] {
      const int cell = sculpture.rest().faceCells()[selected][0];
      sculpture.deleteCell(cell);
      selected = -1;
      pulling = false;
      message = "deleted cell " + std::to_string(cell);
    });
  }

  void fixSelected(bool fix) {
    if (!requireSelection()) return;
    act([&] {
      const std::vector<int>& points = sculpture.rest().faces()[selected];
      fix ? sculpture.fix(points) : sculpture.unfix(points);
      message = std::string(fix ? "fixed" : "unfixed") + " the " + std::to_string(points.size()) +
                " points of face " + std::to_string(selected);
    });
  }

  // The control point drawn within kPickPixels of a display position, or -1.
  int controlPointAt(int x, int y) {
    vtkRenderer* r = view.renderer();
    const MatrixX3& p = sculpture.model().controlPoints();
    int best = -1;
    double nearest = kPickPixels;
    for (int i = 0; i < p.rows(); ++i) {
      const Vector3 d = style::displayAt(r, p.row(i).transpose());
      const double distance = std::hypot(d.x() - x, d.y() - y);
      if (distance <= nearest) {
        nearest = distance;
        best = i;
      }
    }
    return best;
  }

  // Fixes a free control point or frees a fixed one; false if none is there.
  bool toggleFixedAt(int x, int y) {
    if (!view.controlLatticeShown()) return false;
    const int point = controlPointAt(x, y);
    if (point < 0) return false;
    act([&] {
      const bool fixed = sculpture.model().fixed()[point];
      fixed ? sculpture.unfix({point}) : sculpture.fix({point});
      message = std::string(fixed ? "unfixed" : "fixed") + " control point " + std::to_string(point);
    });
    return true;
  }

  void scaleMaterial(double stiffness, double damping) {
    act([&] {
      SolidMaterial m = sculpture.settings().material;
      m.springStiffness *= stiffness;
      m.virtualStiffness *= stiffness;
      m.damping *= damping;
      sculpture.setMaterial(m);
      message = "material changed";
    });
  }

  void saveNow() {
    if (!save) {
      message = "no save action";
      redraw();
      return;
    }
    act([&] { message = save(sculpture); });
  }
};

// Routes the mouse and keys to the sculptor; plain drags keep the trackball.
class SculptorStyle : public vtkInteractorStyleTrackballCamera {
 public:
  static SculptorStyle* New();
  vtkTypeMacro(SculptorStyle, vtkInteractorStyleTrackballCamera);
  Sculptor::Impl* sculptor = nullptr;

  void OnLeftButtonDown() override {
    int x, y;
    Interactor->GetEventPosition(x, y);
    if (Interactor->GetControlKey()) {
      sculptor->grab(x, y);
      return;
    }
    if (Interactor->GetShiftKey()) {
      sculptor->select(x, y);
      return;
    }
    vtkInteractorStyleTrackballCamera::OnLeftButtonDown();
  }

  void OnMouseMove() override {
    if (sculptor->pulling) {
      int x, y;
      Interactor->GetEventPosition(x, y);
      sculptor->pullTo(x, y);
      return;
    }
    vtkInteractorStyleTrackballCamera::OnMouseMove();
  }

  void OnLeftButtonUp() override {
    if (sculptor->pulling) {
      sculptor->pulling = false;
      sculptor->act([&] {
        sculptor->sculpture.release();
        sculptor->message = "rope released";
      });
      return;
    }
    vtkInteractorStyleTrackballCamera::OnLeftButtonUp();
  }

  void OnRightButtonDown() override {
    int x, y;
    Interactor->GetEventPosition(x, y);
    if (sculptor->toggleFixedAt(x, y)) return;
    vtkInteractorStyleTrackballCamera::OnRightButtonDown();
  }

  void OnKeyPress() override {
    const std::string key = Interactor->GetKeySym() ? Interactor->GetKeySym() : "";
    Sculptor::Impl& s = *sculptor;
    if (key == "e") {
      s.extrude();
    } else if (key == "d" || key == "Delete") {
      s.deleteCell();
    } else if (key == "f") {
      s.fixSelected(true);
    } else if (key == "u") {
      s.fixSelected(false);
    } else if (key == "U") {
      s.act([&] {
        s.sculpture.unfixAll();
        s.message = "unfixed all";
      });
    } else if (key == "p") {
      s.act([&] {
        s.sculpture.plasticity();
        s.message = "plasticity: the current shape is the rest shape";
      });
    } else if (key == "k" || key == "K") {
      s.scaleMaterial(key == "K" ? 1.25 : 0.8, 1.0);
    } else if (key == "g" || key == "G") {
      s.scaleMaterial(1.0, key == "G" ? 1.25 : 0.8);
    } else if (key == "space") {
      s.paused = !s.paused;
      s.message = s.paused ? "paused" : "running";
      s.redraw();
    } else if (key == "w") {
      s.view.showControlLattice(!s.view.controlLatticeShown());
      s.redraw();
    } else if (key == "c") {
      s.view.resetCamera();
      s.redraw();
    } else if (key == "s") {
      s.saveNow();
    } else if (key == "h") {
      s.helpText->SetVisibility(!s.helpText->GetVisibility());
      s.redraw();
    } else if (key == "q" || key == "Escape") {
      Interactor->ExitCallback();
    }
  }

  // VTK's default single-key bindings (wireframe, stereo, ...) would act on
  // every prop; the sculptor's own keys are handled in OnKeyPress.
  void OnChar() override {}
};

vtkStandardNewMacro(SculptorStyle);

Sculptor::Sculptor(const Lattice& control, const SculptSettings& settings,
                   std::function<std::string(const Sculpture&)> save) {
  std::string why;
  if (!displayAvailable(&why)) throw Error("the sculpting window needs an X display: " + why);
  impl_ = std::make_unique<Impl>(control, settings, std::move(save));
  Impl& s = *impl_;
  s.window->SetSize(1000, 800);
  s.window->SetMultiSamples(0);
  s.window->SetWindowName("DynSub: sculpt");
  s.window->SetNumberOfLayers(2);
  s.interactor->SetRenderWindow(s.window);
  vtkNew<SculptorStyle> style;
  style->sculptor = impl_.get();
  s.interactor->SetInteractorStyle(style);

  s.window->AddRenderer(s.view.renderer());
  s.view.show(s.sculpture);
  s.view.resetCamera();

  s.overlay->SetLayer(1);
  s.overlay->InteractiveOff();
  style::helpOverlay(s.overlay, s.helpText, kHelp, 0.01, 0.99);
  style::cornerText(s.statusText, 0.01, 0.01, style::Corner::BottomLeft, 13);
  s.statusText->GetTextProperty()->SetBackgroundColor(0, 0, 0);
  s.statusText->GetTextProperty()->SetBackgroundOpacity(0.6);
  s.overlay->AddActor2D(s.statusText);
  s.window->AddRenderer(s.overlay);

  s.picker->SetTolerance(0.0005);
  s.picker->PickFromListOn();
  s.picker->AddPickList(s.view.surfaceActor());

  style::observeTimer(
      s.interactor, s.timerCommand, [](void* client) { static_cast<Sculptor::Impl*>(client)->tick(); },
      impl_.get());
  s.updateStatus();
}

Sculptor::~Sculptor() = default;

vtkRenderWindow* Sculptor::window() const { return impl_->window; }
vtkRenderWindowInteractor* Sculptor::interactor() const { return impl_->interactor; }

void Sculptor::run() {
  impl_->interactor->Initialize();
  impl_->interactor->CreateRepeatingTimer(kTickMilliseconds);
  impl_->redraw();
  impl_->interactor->Start();
}

const Sculpture& Sculptor::sculpture() const { return impl_->sculpture; }
SolidView& Sculptor::view() const { return impl_->view; }
int Sculptor::selectedFace() const { return impl_->selected; }
bool Sculptor::paused() const { return impl_->paused; }

void Sculptor::advance(int ticks) {
  for (int i = 0; i < ticks; ++i) impl_->tick();
}

std::string Sculptor::status() const {
  impl_->updateStatus();
  return impl_->statusText->GetInput() ? impl_->statusText->GetInput() : "";
}

}  // namespace dynsub
