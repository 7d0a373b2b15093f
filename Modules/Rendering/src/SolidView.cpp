#include "dynsub/SolidView.h"

#include <algorithm>
#include <array>

#include <vtkActor.h>
#include <vtkCamera.h>
#include <vtkCellArray.h>
#include <vtkCellData.h>
#include <vtkNew.h>
#include <vtkPointData.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkPolyDataMapper.h>
#include <vtkPolyDataNormals.h>
#include <vtkProperty.h>
#include <vtkRenderWindow.h>
#include <vtkRenderer.h>
#include <vtkUnsignedCharArray.h>

#include "dynsub/SceneStyle.h"
#include "dynsub/Figures.h"
#include "dynsub/Sculpting.h"

namespace dynsub {

namespace {

constexpr std::array<unsigned char, 3> kClay{214, 156, 112};
constexpr std::array<unsigned char, 3> kSelectedFace{60, 210, 230};
constexpr std::array<unsigned char, 3> kFreePoint{235, 235, 235};
constexpr std::array<unsigned char, 3> kFixedPoint{230, 40, 40};
constexpr double kControlPointPixels = 8.0;

vtkSmartPointer<vtkPoints> pointsOf(const MatrixX3& p) {
  auto points = vtkSmartPointer<vtkPoints>::New();
  points->SetDataTypeToDouble();
  points->SetNumberOfPoints(p.rows());
  for (Eigen::Index i = 0; i < p.rows(); ++i) points->SetPoint(i, p(i, 0), p(i, 1), p(i, 2));
  return points;
}

vtkSmartPointer<vtkUnsignedCharArray> colourArray() {
  auto colours = vtkSmartPointer<vtkUnsignedCharArray>::New();
  colours->SetNumberOfComponents(3);
  colours->SetName("Colours");
  return colours;
}

}  // namespace

struct SolidView::Impl {
  vtkNew<vtkRenderer> renderer;
  vtkNew<vtkPolyData> surface;  // the refined lattice's boundary faces
  vtkNew<vtkPolyDataNormals> normals;
  vtkNew<vtkActor> surfaceActor;
  vtkNew<vtkPolyData> lattice;  // control lattice edges
  vtkNew<vtkActor> latticeActor;
  vtkNew<vtkPolyData> controlPoints;
  vtkNew<vtkActor> pointActor;
  vtkNew<vtkPolyData> rope;
  vtkNew<vtkActor> ropeActor;
  std::vector<int> faceOrigin;  // control face of each drawn surface cell

  Impl() {
    renderer->SetBackground(0.1, 0.1, 0.12);
    // Shared vertex normals over the whole boundary: the refined faces are
    // small pieces of a smooth surface.
    normals->SetInputData(surface);
    normals->SplittingOff();
    normals->ConsistencyOff();  // boundary faces are already oriented outwards
    normals->AutoOrientNormalsOff();
    normals->ComputeCellNormalsOff();
    vtkNew<vtkPolyDataMapper> surfaceMapper;
    surfaceMapper->SetInputConnection(normals->GetOutputPort());
    surfaceMapper->SetScalarModeToUseCellData();
    surfaceMapper->SetColorModeToDirectScalars();
    surfaceActor->SetMapper(surfaceMapper);
    surfaceActor->GetProperty()->SetSpecular(0.25);
    surfaceActor->GetProperty()->SetSpecularPower(25);
    renderer->AddActor(surfaceActor);

    vtkNew<vtkPolyDataMapper> latticeMapper;
    latticeMapper->SetInputData(lattice);
    latticeActor->SetMapper(latticeMapper);
    latticeActor->GetProperty()->SetColor(0.55, 0.7, 1.0);
    latticeActor->GetProperty()->SetLineWidth(1.5);
    latticeActor->GetProperty()->LightingOff();
    renderer->AddActor(latticeActor);

    vtkNew<vtkPolyDataMapper> pointMapper;
    pointMapper->SetInputData(controlPoints);
    pointMapper->SetColorModeToDirectScalars();
    pointActor->SetMapper(pointMapper);
    style::pointsAsDots(pointActor, kControlPointPixels);
    renderer->AddActor(pointActor);

    vtkNew<vtkPolyDataMapper> ropeMapper;
    ropeMapper->SetInputData(rope);
    ropeActor->SetMapper(ropeMapper);
    ropeActor->GetProperty()->SetColor(0.3, 0.95, 0.4);
    ropeActor->GetProperty()->SetLineWidth(3);
    ropeActor->GetProperty()->SetPointSize(10);
    ropeActor->GetProperty()->RenderPointsAsSpheresOn();
    ropeActor->GetProperty()->LightingOff();
    renderer->AddActor(ropeActor);
  }

  void show(const Sculpture& s, int selectedFace) {
    const SolidModel& model = s.model();
    const SolidRefinement& refined = model.refinement();
    const MatrixX3 d = model.dataPoints();

    vtkNew<vtkCellArray> faces;
    auto colours = colourArray();
    faceOrigin.clear();
    for (int f = 0; f < refined.lattice.faceCount(); ++f) {
      if (!refined.lattice.isBoundaryFace(f)) continue;
      std::vector<int> loop = refined.lattice.faces()[f];
      // Drawn counter-clockwise seen from outside, whatever the file said
      // (lighting and picking rely on outward normals).
      if (!facesAwayFrom(refined.lattice, f, refined.lattice.faceCells()[f][0])) std::reverse(loop.begin(), loop.end());
      faces->InsertNextCell(static_cast<vtkIdType>(loop.size()));
      for (int p : loop) faces->InsertCellPoint(p);
      faceOrigin.push_back(refined.faceOrigin[f]);
      colours->InsertNextTypedTuple(
          (selectedFace >= 0 && refined.faceOrigin[f] == selectedFace ? kSelectedFace : kClay).data());
    }
    surface->Initialize();
    surface->SetPoints(pointsOf(d));
    surface->SetPolys(faces);
    surface->GetCellData()->SetScalars(colours);
    surface->Modified();

    const MatrixX3& p = model.controlPoints();
    const Lattice& control = model.control();
    vtkNew<vtkCellArray> edges;
    for (const auto& [a, b] : control.edges()) {
      const vtkIdType ids[2] = {a, b};
      edges->InsertNextCell(2, ids);
    }
    lattice->Initialize();
    lattice->SetPoints(pointsOf(p));
    lattice->SetLines(edges);
    lattice->Modified();

    vtkNew<vtkCellArray> vertices;
    auto pointColours = colourArray();
    for (vtkIdType i = 0; i < p.rows(); ++i) {
      vertices->InsertNextCell(1, &i);
      pointColours->InsertNextTypedTuple((model.fixed()[i] ? kFixedPoint : kFreePoint).data());
    }
    controlPoints->Initialize();
    controlPoints->SetPoints(lattice->GetPoints());
    controlPoints->SetVerts(vertices);
    controlPoints->GetPointData()->SetScalars(pointColours);
    controlPoints->Modified();

    rope->Initialize();
    if (model.ropePoint() >= 0) {
      MatrixX3 ends(2, 3);
      ends.row(0) = d.row(model.ropePoint());
      ends.row(1) = model.ropeTarget().transpose();
      vtkNew<vtkCellArray> line, end;
      const vtkIdType ids[2] = {0, 1};
      line->InsertNextCell(2, ids);
      end->InsertNextCell(1, &ids[1]);
      rope->SetPoints(pointsOf(ends));
      rope->SetLines(line);
      rope->SetVerts(end);
    }
    rope->Modified();
  }

  void resetCamera() {
    double bounds[6];
    surface->GetBounds(bounds);
    const Vector3 centre(0.5 * (bounds[0] + bounds[1]), 0.5 * (bounds[2] + bounds[3]), 0.5 * (bounds[4] + bounds[5]));
    vtkCamera* camera = renderer->GetActiveCamera();
    camera->SetFocalPoint(centre.data());
    const Vector3 eye = centre + Vector3(0.8, -1.6, 1.1);  // front (-y), right (+x), above (+z)
    camera->SetPosition(eye.data());
    camera->SetViewUp(0, 0, 1);
    renderer->ResetCamera(bounds);
    renderer->ResetCameraClippingRange();
  }
};

SolidView::SolidView() : impl_(std::make_unique<Impl>()) {}
SolidView::~SolidView() = default;

vtkRenderer* SolidView::renderer() const { return impl_->renderer; }
vtkActor* SolidView::surfaceActor() const { return impl_->surfaceActor; }
void SolidView::show(const Sculpture& sculpture, int selectedFace) { impl_->show(sculpture, selectedFace); }

void SolidView::showControlLattice(bool visible) {
  impl_->latticeActor->SetVisibility(visible);
  impl_->pointActor->SetVisibility(visible);
}

bool SolidView::controlLatticeShown() const { return impl_->latticeActor->GetVisibility(); }

int SolidView::controlFaceOf(vtkIdType surfaceCell) const {
  if (surfaceCell < 0 || surfaceCell >= static_cast<vtkIdType>(impl_->faceOrigin.size())) return -1;
  return impl_->faceOrigin[surfaceCell];
}

void SolidView::resetCamera() { impl_->resetCamera(); }

vtkSmartPointer<vtkRenderWindow> sculptureFigure(const Sculpture& sculpture) {
  auto window = style::offScreenWindow(800, 800);
  // The view lives as long as the window: the renderer and its actors are
  // reference counted and stay with the window.
  SolidView view;
  view.show(sculpture);
  view.resetCamera();
  window->AddRenderer(view.renderer());
  return window;
}

void writeSculptureFigure(const Sculpture& sculpture, const std::string& path) {
  writePng(sculptureFigure(sculpture), path);
}

}  // namespace dynsub
